// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/Frd.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ictk::mesh
{

namespace
{

constexpr std::size_t none = std::numeric_limits<std::size_t>::max();

/// Nodes per .frd element type (1 he8, 2 pe6, 3 te4, 4 he20, 5 pe15, 6 te10, 7 tr3, 8 tr6,
/// 9 qu4, 10 qu8, 11 be2, 12 be3).
int nodesOfType(int type)
{
  static const int count[] = { 0, 8, 6, 4, 20, 15, 10, 3, 6, 4, 8, 2, 3 };
  return type >= 1 && type <= 12 ? count[type] : 0;
}

class Reader
{
public:
  explicit Reader(const std::string& path)
    : path_(path)
    , in_(path)
  {
    if (!in_)
    {
      throw std::runtime_error("cannot read '" + path + "'");
    }
  }

  bool next()
  {
    if (!std::getline(in_, line_))
    {
      return false;
    }
    if (!line_.empty() && line_.back() == '\r')
    {
      line_.pop_back();
    }
    ++number_;
    return true;
  }
  const std::string& line() const { return line_; }

  [[noreturn]] void fail(const std::string& what) const
  {
    throw std::runtime_error(path_ + ":" + std::to_string(number_) + ": " + what);
  }

  /// Columns [at, at + width) of the line, trimmed.
  std::string field(std::size_t at, std::size_t width) const
  {
    if (at >= line_.size())
    {
      return {};
    }
    std::string s = line_.substr(at, width);
    const auto b = s.find_first_not_of(' ');
    const auto e = s.find_last_not_of(' ');
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  }
  long long integer(std::size_t at, std::size_t width, const char* what) const
  {
    const std::string s = field(at, width);
    char* end = nullptr;
    const long long v = s.empty() ? 0 : std::strtoll(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0')
    {
      fail(std::string("expected ") + what + " in columns " + std::to_string(at + 1) + "-" +
        std::to_string(at + width) + ", found '" + s + "'");
    }
    return v;
  }
  double real(std::size_t at, std::size_t width, const char* what) const
  {
    const std::string s = field(at, width);
    char* end = nullptr;
    const double v = s.empty() ? 0 : std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0')
    {
      fail(std::string("expected ") + what + " in columns " + std::to_string(at + 1) + "-" +
        std::to_string(at + width) + ", found '" + s + "'");
    }
    return v;
  }
  /// The whitespace-separated words of the line.
  std::vector<std::string> words() const
  {
    std::istringstream s(line_);
    std::vector<std::string> w;
    std::string x;
    while (s >> x)
    {
      w.push_back(x);
    }
    return w;
  }
  /// The record key: the first 3 columns ( -1, -2, -3, -4, -5) or the word of a header line.
  std::string key() const { return line_.substr(0, std::min<std::size_t>(3, line_.size())); }

private:
  std::string path_;
  std::ifstream in_;
  std::string line_;
  std::size_t number_ = 0;
};

/// The format of a block header's last word: 0 (short: numbers of 5 columns), 1 (long: 10);
/// 2 (binary) is refused.
int formatOf(const Reader& r)
{
  const auto w = r.words();
  const std::string& last = w.back();
  if (w.size() < 3 || (last != "0" && last != "1"))
  {
    if (!w.empty() && last == "2")
    {
      r.fail("a binary .frd block (ccx's *NODE FILE has no OUTPUT=ASCII here): only the ASCII "
             "format is read");
    }
    r.fail("expected the block's format (0 or 1) as its last word");
  }
  return last == "1" ? 1 : 0;
}

void readNodes(Reader& r, FrdResults& out)
{
  const int format = formatOf(r);
  const std::size_t width = format == 1 ? 10 : 5;
  while (r.next())
  {
    const std::string key = r.key();
    if (key == " -3")
    {
      return;
    }
    if (key != " -1")
    {
      r.fail("expected a node record ' -1' or the block's end ' -3'");
    }
    const long long id = r.integer(3, width, "a node number");
    if (id < 1)
    {
      r.fail("node number " + std::to_string(id) + " is not positive");
    }
    Point3 p;
    for (std::size_t a = 0; a < 3; ++a)
    {
      p[a] = r.real(3 + width + 12 * a, 12, "a coordinate");
    }
    out.nodeIds.push_back(static_cast<std::size_t>(id));
    out.points.push_back(p);
  }
  r.fail("the node block has no end ' -3'");
}

void readElements(Reader& r, FrdResults& out)
{
  const int format = formatOf(r);
  const std::size_t width = format == 1 ? 10 : 5;
  FrdElement* current = nullptr;
  std::size_t expected = 0;
  while (r.next())
  {
    const std::string key = r.key();
    if (key == " -3")
    {
      if (current && current->nodes.size() != expected)
      {
        r.fail("element " + std::to_string(current->id) + " has " +
          std::to_string(current->nodes.size()) + " nodes, its type needs " +
          std::to_string(expected));
      }
      return;
    }
    if (key == " -1")
    {
      if (current && current->nodes.size() != expected)
      {
        r.fail("element " + std::to_string(current->id) + " has " +
          std::to_string(current->nodes.size()) + " nodes, its type needs " +
          std::to_string(expected));
      }
      FrdElement e;
      e.id = static_cast<std::size_t>(r.integer(3, width, "an element number"));
      e.type = static_cast<int>(r.integer(3 + width, 5, "an element type"));
      const int n = nodesOfType(e.type);
      if (n == 0)
      {
        r.fail("unknown element type " + std::to_string(e.type));
      }
      expected = static_cast<std::size_t>(n);
      out.elements.push_back(std::move(e));
      current = &out.elements.back();
    }
    else if (key == " -2")
    {
      if (!current)
      {
        r.fail("element nodes ' -2' before an element ' -1'");
      }
      for (std::size_t at = 3; at < r.line().size(); at += width)
      {
        if (r.field(at, width).empty())
        {
          break;
        }
        current->nodes.push_back(static_cast<std::size_t>(r.integer(at, width, "a node number")));
      }
      if (current->nodes.size() > expected)
      {
        r.fail("element " + std::to_string(current->id) + " has more nodes than its type's " +
          std::to_string(expected));
      }
    }
    else
    {
      r.fail("expected an element record ' -1', ' -2' or the block's end ' -3'");
    }
  }
  r.fail("the element block has no end ' -3'");
}

void readResults(Reader& r, FrdResults& out)
{
  // "  100CL  101 1.000000000           4 ...": key, 6 columns of set name, the time (12), the
  // node count (12), ..., the format last.
  FrdBlock block;
  block.time = r.real(12, 12, "the step time");
  const int format = formatOf(r);
  const std::size_t width = format == 1 ? 10 : 5;
  if (!r.next() || r.key() != " -4")
  {
    r.fail("expected the result block's header ' -4'");
  }
  block.name = r.field(5, 8);
  // " -5" lines: name (8 columns from 6), then menu, type, index 1, index 2, exists (5 each); a
  // component with exists = 1 (DISP's "ALL") is computed by the viewer and has no values.
  std::size_t lineLength = 0;
  while (r.next() && r.key() == " -5")
  {
    if (r.field(33, 5) != "1")
    {
      block.components.push_back(r.field(5, 8));
    }
    lineLength = r.line().size();
  }
  if (lineLength == 0)
  {
    r.fail("result block " + block.name + " has no components ' -5'");
  }
  const std::size_t n = block.components.size();
  block.values.assign(out.nodes() * n, std::numeric_limits<double>::quiet_NaN());
  std::size_t node = none, filled = 0;
  auto finish = [&]()
  {
    if (node != none && filled != n)
    {
      r.fail("node " + std::to_string(out.nodeIds[node]) + " of block " + block.name + " has " +
        std::to_string(filled) + " values, not " + std::to_string(n));
    }
  };
  // The current line is the first after the components.
  do
  {
    const std::string key = r.key();
    if (key == " -3")
    {
      finish();
      out.blocks[block.name] = std::move(block);
      return;
    }
    std::size_t at = 3;
    if (key == " -1")
    {
      finish();
      const long long id = r.integer(3, width, "a node number");
      node =
        id >= 1 && std::size_t(id) < out.indexOfId.size() ? out.indexOfId[std::size_t(id)] : none;
      if (node == none)
      {
        r.fail("node " + std::to_string(id) + " is not in the node block");
      }
      filled = 0;
      at += width;
    }
    else if (key != " -2" || node == none)
    {
      r.fail("expected a result record ' -1', its continuation ' -2' or the block's end ' -3'");
    }
    else
    {
      at += width; // a continuation leaves the node number's columns blank
    }
    for (; at + 12 <= r.line().size() && filled < n; at += 12)
    {
      block.values[node * n + filled++] = r.real(at, 12, "a value");
    }
  } while (r.next());
  r.fail("result block " + block.name + " has no end ' -3'");
}

template <std::size_t N>
std::vector<std::array<double, N>> tuples(
  const FrdResults& results, const std::string& name, const std::string& path)
{
  std::vector<std::array<double, N>> out;
  const auto it = results.blocks.find(name);
  if (it == results.blocks.end())
  {
    return out;
  }
  if (it->second.components.size() != N)
  {
    throw std::runtime_error(path + ": block " + name + " has " +
      std::to_string(it->second.components.size()) + " components, not " + std::to_string(N));
  }
  out.resize(results.nodes());
  for (std::size_t i = 0; i < out.size(); ++i)
  {
    std::copy_n(it->second.values.begin() + static_cast<std::ptrdiff_t>(i * N), N, out[i].begin());
  }
  return out;
}

} // namespace

std::size_t FrdResults::index(std::size_t id) const
{
  const std::size_t i = id < indexOfId.size() ? indexOfId[id] : none;
  if (i == none)
  {
    throw std::out_of_range("node " + std::to_string(id) + " is not in the results");
  }
  return i;
}

FrdResults readFrd(const std::string& path)
{
  Reader r(path);
  FrdResults out;
  bool ended = false;
  while (r.next())
  {
    const auto w = r.words();
    if (w.empty())
    {
      continue;
    }
    const std::string& first = w[0];
    if (first == "9999")
    {
      ended = true;
      break;
    }
    if (first == "2C")
    {
      if (!out.nodeIds.empty())
      {
        r.fail("a second node block");
      }
      readNodes(r, out);
      std::size_t largest = 0;
      for (auto id : out.nodeIds)
      {
        largest = std::max(largest, id);
      }
      if (largest > 16 * out.nodeIds.size() + 1024)
      {
        r.fail("node numbers up to " + std::to_string(largest) + " for " +
          std::to_string(out.nodeIds.size()) + " nodes");
      }
      out.indexOfId.assign(largest + 1, none);
      for (std::size_t i = 0; i < out.nodeIds.size(); ++i)
      {
        if (out.indexOfId[out.nodeIds[i]] != none)
        {
          r.fail("node " + std::to_string(out.nodeIds[i]) + " appears twice");
        }
        out.indexOfId[out.nodeIds[i]] = i;
      }
    }
    else if (first == "3C")
    {
      readElements(r, out);
    }
    else if (first.rfind("100C", 0) == 0)
    {
      if (out.nodeIds.empty())
      {
        r.fail("a result block before the node block");
      }
      readResults(r, out);
    }
    else if (first == "1C" || first[0] == '1' || first == "-4" || first == "-5")
    {
      // Header lines: 1C (model), 1U... (user text), 1PSTEP (step).
      if (first == "-4" || first == "-5")
      {
        r.fail("a result header outside a result block");
      }
    }
    else
    {
      r.fail("unexpected record '" + first + "'");
    }
  }
  if (out.nodeIds.empty())
  {
    throw std::runtime_error("'" + path + "' has no nodes: not a CalculiX results file");
  }
  if (!ended)
  {
    r.fail("the file ends without '9999' (truncated?)");
  }
  out.displacement = tuples<3>(out, "DISP", path);
  out.stress = tuples<6>(out, "STRESS", path);
  out.force = tuples<3>(out, "FORC", path);
  return out;
}

double vonMises(const std::array<double, 6>& s)
{
  const double a = s[0] - s[1], b = s[1] - s[2], c = s[2] - s[0];
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

PointResults resultsOnMesh(const TetMesh& mesh, const FrdResults& results)
{
  if (results.nodes() != mesh.points.size())
  {
    throw std::invalid_argument("the results have " + std::to_string(results.nodes()) +
      " nodes, the mesh " + std::to_string(mesh.points.size()) + " points");
  }
  double extent = 0;
  for (const auto& p : mesh.points)
  {
    extent = std::max({ extent, std::abs(p[0]), std::abs(p[1]), std::abs(p[2]) });
  }
  const double tolerance = 1e-4 * std::max(extent, 1e-300);
  PointResults out;
  const bool u = !results.displacement.empty(), s = !results.stress.empty();
  out.displacement.resize(u ? mesh.points.size() : 0);
  out.stress.resize(s ? mesh.points.size() : 0);
  out.vonMises.resize(s ? mesh.points.size() : 0);
  const bool f = !results.force.empty();
  out.force.resize(f ? mesh.points.size() : 0);
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
  {
    const std::size_t k = i + 1 < results.indexOfId.size() ? results.indexOfId[i + 1] : none;
    if (k == none)
    {
      throw std::invalid_argument("the results have no node " + std::to_string(i + 1) +
        " (mesh point " + std::to_string(i) + ")");
    }
    for (std::size_t a = 0; a < 3; ++a)
    {
      if (std::abs(results.points[k][a] - mesh.points[i][a]) > tolerance)
      {
        throw std::invalid_argument("node " + std::to_string(i + 1) +
          " of the results is not at mesh point " + std::to_string(i) +
          ": the results are of another mesh");
      }
    }
    if (u)
    {
      out.displacement[i] = results.displacement[k];
    }
    if (s)
    {
      out.stress[i] = results.stress[k];
      out.vonMises[i] = vonMises(results.stress[k]);
    }
    if (f)
    {
      out.force[i] = results.force[k];
    }
  }
  return out;
}

} // namespace ictk::mesh
