// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Expr.h"

#include "FRep/Kernels.h"

#include <functional>

#include <cmath>
#include <cstring>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace ictk::frep
{

namespace
{
struct OpcodeInfo
{
  const char* name;
  int arity;
};

// clang-format off
constexpr OpcodeInfo opcodeTable[] = {
  { "const", 0 }, { "var", 0 }, { "param", 0 }, { "neg", 1 }, { "abs", 1 }, { "sqrt", 1 },
  { "square", 1 }, { "exp", 1 }, { "log", 1 }, { "sin", 1 }, { "cos", 1 }, { "tan", 1 },
  { "asin", 1 }, { "acos", 1 }, { "atan", 1 }, { "sign", 1 }, { "floor", 1 }, { "add", 2 }, { "sub", 2 },
  { "mul", 2 }, { "div", 2 }, { "min", 2 }, { "max", 2 }, { "pow", 2 }, { "atan2", 2 },
  { "select", 3 }, { "cauchySegment", 3 },
};
// clang-format on
static_assert(sizeof(opcodeTable) / sizeof(opcodeTable[0]) == static_cast<int>(Opcode::Count_),
  "opcode table out of date");

std::uint64_t doubleBits(double v)
{
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}
} // namespace

namespace
{
template <typename T>
T cauchySegmentTerms(T u, T v, T length)
{
  const T p2 = T(1) + v;
  const T p = std::sqrt(p2);
  const T w = length - u;
  const T rational = u / (T(2) * p2 * (p2 + u * u)) + w / (T(2) * p2 * (p2 + w * w));
  const T angular = (std::atan(u / p) + std::atan(w / p)) / (T(2) * p2 * p);
  return rational + angular;
}
} // namespace

double detail::cauchySegment(double u, double v, double length)
{
  return cauchySegmentTerms(u, v, length);
}

float detail::cauchySegment(float u, float v, float length)
{
  return cauchySegmentTerms(u, v, length);
}

const char* axisName(Axis a)
{
  static const char* names[] = { "x", "y", "z", "t" };
  return names[static_cast<int>(a)];
}

int opcodeArity(Opcode op)
{
  return opcodeTable[static_cast<int>(op)].arity;
}

const char* opcodeName(Opcode op)
{
  return opcodeTable[static_cast<int>(op)].name;
}

// A node is identified by its key: the opcode, the children's identities and the leaf payload.
struct NodeKey
{
  Opcode op;
  std::uint64_t payload; // constant bits, axis or parameter slot
  const Node* children[3];

  bool operator==(const NodeKey& o) const
  {
    return op == o.op && payload == o.payload && children[0] == o.children[0] &&
      children[1] == o.children[1] && children[2] == o.children[2];
  }
};

struct NodeKeyHash
{
  std::size_t operator()(const NodeKey& k) const
  {
    std::size_t h = std::hash<std::uint64_t>()(k.payload) ^ (static_cast<std::size_t>(k.op) << 1);
    for (const Node* c : k.children)
    {
      h ^= std::hash<const void*>()(c) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    }
    return h;
  }
};

class Node
{
public:
  Node(const NodeKey& key, std::vector<Expr> children, std::uint8_t axes)
    : key_(key)
    , children_(std::move(children))
    , axes_(axes)
  {
  }
  ~Node();

  static Expr intern(Opcode op, std::uint64_t payload, std::vector<Expr> children);

  NodeKey key_;
  std::vector<Expr> children_;
  std::uint8_t axes_;
};

namespace
{
// The hash-consing table. Entries are weak so the table never keeps a model alive. The mutex is
// recursive because destroying a node releases its children, whose destructors erase their own
// entries while the parent's erase may already hold the lock.
struct NodeTable
{
  std::recursive_mutex mutex;
  std::unordered_map<NodeKey, std::weak_ptr<const Node>, NodeKeyHash> nodes;
};

NodeTable& nodeTable()
{
  // Leaked on purpose: nodes held in static storage elsewhere may be destroyed after this table.
  static NodeTable* table = new NodeTable;
  return *table;
}
} // namespace

std::size_t Expr::liveNodeCount()
{
  NodeTable& table = nodeTable();
  std::lock_guard<std::recursive_mutex> lock(table.mutex);
  std::size_t live = 0;
  for (const auto& entry : table.nodes)
  {
    live += entry.second.expired() ? 0 : 1;
  }
  return live;
}

Node::~Node()
{
  {
    NodeTable& table = nodeTable();
    std::lock_guard<std::recursive_mutex> lock(table.mutex);
    auto it = table.nodes.find(key_);
    if (it != table.nodes.end() && it->second.expired())
    {
      table.nodes.erase(it);
    }
  }
  // Releasing children recursively would overflow the stack on long chains (a union of 10^5
  // shapes): the outermost destructor drains a per-thread queue instead.
  thread_local std::vector<Expr> pending;
  thread_local bool draining = false;
  for (Expr& c : children_)
  {
    pending.push_back(std::move(c));
  }
  children_.clear();
  if (draining)
  {
    return;
  }
  draining = true;
  while (!pending.empty())
  {
    Expr last = std::move(pending.back());
    pending.pop_back();
  }
  draining = false;
}

Expr Node::intern(Opcode op, std::uint64_t payload, std::vector<Expr> children)
{
  NodeKey key{ op, payload, { nullptr, nullptr, nullptr } };
  std::uint8_t axes = 0;
  const int n = opcodeArity(op);
  for (int i = 0; i < n; ++i)
  {
    key.children[i] = children[i].node_.get();
    axes |= children[i].node_->axes_;
  }
  if (op == Opcode::Variable)
  {
    axes = static_cast<std::uint8_t>(1u << payload);
  }
  NodeTable& table = nodeTable();
  std::lock_guard<std::recursive_mutex> lock(table.mutex);
  auto& slot = table.nodes[key];
  if (auto existing = slot.lock())
  {
    return Expr(std::move(existing));
  }
  auto node = std::make_shared<const Node>(key, std::move(children), axes);
  slot = node;
  return Expr(std::move(node));
}

Expr::Expr()
  : Expr(constant(0.0))
{
}

Expr::Expr(double value)
  : Expr(constant(value))
{
}

Expr Expr::constant(double value)
{
  // -0.0 and 0.0 compare equal but are different nodes; normalise so that folding is stable.
  if (value == 0.0)
  {
    value = 0.0;
  }
  return Node::intern(Opcode::Constant, doubleBits(value), {});
}

Expr Expr::variable(Axis axis)
{
  return Node::intern(Opcode::Variable, static_cast<std::uint64_t>(axis), {});
}

Expr Expr::parameter(std::uint32_t slot)
{
  return Node::intern(Opcode::Parameter, slot, {});
}

Opcode Expr::opcode() const
{
  return node_->key_.op;
}

int Expr::arity() const
{
  return opcodeArity(opcode());
}

const Expr& Expr::child(int i) const
{
  if (i < 0 || i >= arity())
  {
    throw std::out_of_range("Expr::child: index out of range");
  }
  return node_->children_[i];
}

double Expr::constantValue() const
{
  if (opcode() != Opcode::Constant)
  {
    throw std::logic_error("Expr::constantValue: not a constant");
  }
  double v;
  std::memcpy(&v, &node_->key_.payload, sizeof v);
  return v;
}

Axis Expr::axis() const
{
  if (opcode() != Opcode::Variable)
  {
    throw std::logic_error("Expr::axis: not a variable");
  }
  return static_cast<Axis>(node_->key_.payload);
}

std::uint32_t Expr::parameterSlot() const
{
  if (opcode() != Opcode::Parameter)
  {
    throw std::logic_error("Expr::parameterSlot: not a parameter");
  }
  return static_cast<std::uint32_t>(node_->key_.payload);
}

std::uint8_t Expr::axesUsed() const
{
  return node_->axes_;
}

void Expr::visitPostOrder(const std::function<void(const Expr&)>& visit) const
{
  // Iterative, so that deep trees (long chains of unions) cannot overflow the stack.
  std::unordered_set<const Node*> done;
  std::vector<std::pair<Expr, int>> stack;
  stack.emplace_back(*this, 0);
  while (!stack.empty())
  {
    auto& [e, next] = stack.back();
    if (next == 0 && done.count(e.id()))
    {
      stack.pop_back();
      continue;
    }
    if (next < e.arity())
    {
      Expr c = e.child(next++);
      if (!done.count(c.id()))
      {
        stack.emplace_back(std::move(c), 0);
      }
      continue;
    }
    done.insert(e.id());
    Expr finished = e;
    stack.pop_back();
    visit(finished);
  }
}

std::size_t Expr::nodeCount() const
{
  std::size_t n = 0;
  visitPostOrder([&n](const Expr&) { ++n; });
  return n;
}

namespace
{
// Rebuilds `root` bottom-up; `leaf` gives the replacement of a node (or null to rebuild it from its
// rewritten children).
Expr rewrite(const Expr& root, const std::function<const Expr*(const Expr&)>& leaf)
{
  std::unordered_map<const Node*, Expr> rewritten;
  root.visitPostOrder(
    [&](const Expr& e)
    {
      Expr r;
      if (const Expr* replacement = leaf(e))
      {
        rewritten.emplace(e.id(), *replacement);
        return;
      }
      switch (e.arity())
      {
        case 0:
          r = e;
          break;
        case 1:
          r = Expr::make(e.opcode(), rewritten.at(e.child(0).id()));
          break;
        case 2:
          r = Expr::make(e.opcode(), rewritten.at(e.child(0).id()), rewritten.at(e.child(1).id()));
          break;
        default:
          r = Expr::make(e.opcode(), rewritten.at(e.child(0).id()), rewritten.at(e.child(1).id()),
            rewritten.at(e.child(2).id()));
          break;
      }
      rewritten.emplace(e.id(), std::move(r));
    });
  return rewritten.at(root.id());
}
} // namespace

Expr Expr::substitute(const std::array<Expr, AxisCount>& map) const
{
  return rewrite(*this,
    [&](const Expr& e) -> const Expr*
    { return e.opcode() == Opcode::Variable ? &map[static_cast<int>(e.axis())] : nullptr; });
}

Expr Expr::replace(const Expr& from, const Expr& to) const
{
  return rewrite(
    *this, [&](const Expr& e) -> const Expr* { return e.identical(from) ? &to : nullptr; });
}

Expr Expr::make(Opcode op, const Expr& a)
{
  if (opcodeArity(op) != 1)
  {
    throw std::logic_error(std::string("Expr::make: ") + opcodeName(op) + " is not unary");
  }
  if (a.isConstant())
  {
    return constant(detail::applyScalar<double>(op, a.constantValue(), 0.0, 0.0));
  }
  if (op == Opcode::Neg && a.opcode() == Opcode::Neg)
  {
    return a.child(0);
  }
  return Node::intern(op, 0, { a });
}

Expr Expr::make(Opcode op, const Expr& a, const Expr& b)
{
  if (opcodeArity(op) != 2)
  {
    throw std::logic_error(std::string("Expr::make: ") + opcodeName(op) + " is not binary");
  }
  if (a.isConstant() && b.isConstant())
  {
    return constant(detail::applyScalar<double>(op, a.constantValue(), b.constantValue(), 0.0));
  }
  // Identities that are exact in IEEE arithmetic for every finite and infinite operand.
  switch (op)
  {
    case Opcode::Add:
      if (a.isConstant(0.0))
        return b;
      if (b.isConstant(0.0))
        return a;
      break;
    case Opcode::Sub:
      if (b.isConstant(0.0))
        return a;
      if (a.isConstant(0.0))
        return make(Opcode::Neg, b);
      break;
    case Opcode::Mul:
      if (a.isConstant(1.0))
        return b;
      if (b.isConstant(1.0))
        return a;
      if (a.isConstant(-1.0))
        return make(Opcode::Neg, b);
      if (b.isConstant(-1.0))
        return make(Opcode::Neg, a);
      break;
    case Opcode::Div:
      if (b.isConstant(1.0))
        return a;
      break;
    case Opcode::Min:
    case Opcode::Max:
      if (a.identical(b))
        return a;
      break;
    default:
      break;
  }
  return Node::intern(op, 0, { a, b });
}

Expr Expr::make(Opcode op, const Expr& a, const Expr& b, const Expr& c)
{
  if (op == Opcode::CauchySegment)
  {
    if (a.isConstant() && b.isConstant() && c.isConstant())
    {
      return constant(
        detail::cauchySegment(a.constantValue(), b.constantValue(), c.constantValue()));
    }
    return Node::intern(op, 0, { a, b, c });
  }
  if (op != Opcode::Select)
  {
    throw std::logic_error(std::string("Expr::make: ") + opcodeName(op) + " is not ternary");
  }
  if (a.isConstant())
  {
    return a.constantValue() >= 0 ? b : c;
  }
  if (b.identical(c))
  {
    return b;
  }
  return Node::intern(op, 0, { a, b, c });
}

Expr operator+(const Expr& a, const Expr& b)
{
  return Expr::make(Opcode::Add, a, b);
}
Expr operator-(const Expr& a, const Expr& b)
{
  return Expr::make(Opcode::Sub, a, b);
}
Expr operator*(const Expr& a, const Expr& b)
{
  return Expr::make(Opcode::Mul, a, b);
}
Expr operator/(const Expr& a, const Expr& b)
{
  return Expr::make(Opcode::Div, a, b);
}
Expr operator-(const Expr& a)
{
  return Expr::make(Opcode::Neg, a);
}
Expr min(const Expr& a, const Expr& b)
{
  return Expr::make(Opcode::Min, a, b);
}
Expr max(const Expr& a, const Expr& b)
{
  return Expr::make(Opcode::Max, a, b);
}
Expr abs(const Expr& a)
{
  return Expr::make(Opcode::Abs, a);
}
Expr sqrt(const Expr& a)
{
  return Expr::make(Opcode::Sqrt, a);
}
Expr square(const Expr& a)
{
  return Expr::make(Opcode::Square, a);
}
Expr exp(const Expr& a)
{
  return Expr::make(Opcode::Exp, a);
}
Expr log(const Expr& a)
{
  return Expr::make(Opcode::Log, a);
}
Expr sin(const Expr& a)
{
  return Expr::make(Opcode::Sin, a);
}
Expr cos(const Expr& a)
{
  return Expr::make(Opcode::Cos, a);
}
Expr tan(const Expr& a)
{
  return Expr::make(Opcode::Tan, a);
}
Expr asin(const Expr& a)
{
  return Expr::make(Opcode::Asin, a);
}
Expr acos(const Expr& a)
{
  return Expr::make(Opcode::Acos, a);
}
Expr atan(const Expr& a)
{
  return Expr::make(Opcode::Atan, a);
}
Expr atan2(const Expr& a, const Expr& b)
{
  return Expr::make(Opcode::Atan2, a, b);
}
Expr sign(const Expr& a)
{
  return Expr::make(Opcode::Sign, a);
}
Expr floor(const Expr& a)
{
  return Expr::make(Opcode::Floor, a);
}
Expr select(const Expr& condition, const Expr& ifTrue, const Expr& ifFalse)
{
  return Expr::make(Opcode::Select, condition, ifTrue, ifFalse);
}

Expr pow(const Expr& a, const Expr& b)
{
  if (b.isConstant())
  {
    const double e = b.constantValue();
    if (e == std::floor(e) && std::fabs(e) <= 64)
    {
      auto n = static_cast<long>(std::fabs(e));
      if (n == 0)
      {
        return Expr(1.0);
      }
      // Exponentiation by squaring: a^n as a product of repeated squares.
      Expr result;
      bool have = false;
      Expr base = a;
      while (n > 0)
      {
        if (n & 1)
        {
          result = have ? result * base : base;
          have = true;
        }
        n >>= 1;
        if (n > 0)
        {
          base = square(base);
        }
      }
      return e < 0 ? Expr(1.0) / result : result;
    }
    if (e == 0.5)
    {
      return sqrt(a);
    }
  }
  return Expr::make(Opcode::Pow, a, b);
}

double evaluateReference(
  const Expr& e, const std::array<double, AxisCount>& p, const std::vector<double>& params)
{
  std::unordered_map<const Node*, double> values;
  e.visitPostOrder(
    [&](const Expr& n)
    {
      double v = 0;
      switch (n.arity())
      {
        case 0:
          if (n.opcode() == Opcode::Constant)
            v = n.constantValue();
          else if (n.opcode() == Opcode::Variable)
            v = p[static_cast<int>(n.axis())];
          else
          {
            const auto slot = n.parameterSlot();
            if (slot >= params.size())
              throw std::out_of_range(
                "evaluateReference: parameter slot " + std::to_string(slot) + " has no value");
            v = params[slot];
          }
          break;
        case 1:
          v = detail::applyScalar<double>(n.opcode(), values.at(n.child(0).id()), 0.0, 0.0);
          break;
        case 2:
          v = detail::applyScalar<double>(
            n.opcode(), values.at(n.child(0).id()), values.at(n.child(1).id()), 0.0);
          break;
        default:
          v = detail::applyScalar<double>(n.opcode(), values.at(n.child(0).id()),
            values.at(n.child(1).id()), values.at(n.child(2).id()));
          break;
      }
      values.emplace(n.id(), v);
    });
  return values.at(e.id());
}

std::string toString(const Expr& e)
{
  std::ostringstream os;
  std::function<void(const Expr&)> print = [&](const Expr& n)
  {
    switch (n.opcode())
    {
      case Opcode::Constant:
        os << n.constantValue();
        return;
      case Opcode::Variable:
        os << axisName(n.axis());
        return;
      case Opcode::Parameter:
        os << "p" << n.parameterSlot();
        return;
      default:
        os << '(' << opcodeName(n.opcode());
        for (int i = 0; i < n.arity(); ++i)
        {
          os << ' ';
          print(n.child(i));
        }
        os << ')';
    }
  };
  print(e);
  return os.str();
}

} // namespace ictk::frep
