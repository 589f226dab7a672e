// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Jit.h"

#include "FRep/Kernels.h"
#include "FRep/TapeDetail.h"

#include <asmjit/x86.h>

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <string>

namespace ictk::frep
{

namespace
{
namespace x86 = asmjit::x86;

// Generated function: axes[a] points to the coordinates of varying axis a (nvec vectors);
// scalars are the uniform values (one float per value id); outs[k] receives varying output k;
// home holds the chunk slots' spill memory; nvec >= 1.
using JitFunction = void (*)(const float* const* axes, const float* scalars, float* const* outs,
  float* home, std::uint64_t nvec);

asmjit::JitRuntime& runtime()
{
  static asmjit::JitRuntime rt; // thread-safe (its allocator locks)
  return rt;
}

// Opcodes compiled to a call of this function once per vector: the interpreter's own scalar
// arithmetic, so the results are the interpreter's.
void callKernel(
  std::uint32_t op, float* out, const float* a, const float* b, const float* c, std::uint64_t n)
{
  const auto code = static_cast<Opcode>(op);
  for (std::uint64_t i = 0; i < n; ++i)
  {
    out[i] = detail::applyScalar<float>(code, a[i], b[i], c[i]);
  }
}

bool native(Opcode op)
{
  switch (op)
  {
    case Opcode::Neg:
    case Opcode::Abs:
    case Opcode::Sqrt:
    case Opcode::Square:
    case Opcode::Add:
    case Opcode::Sub:
    case Opcode::Mul:
    case Opcode::Div:
    case Opcode::Min:
    case Opcode::Max:
    case Opcode::Select:
    case Opcode::Sign:
    case Opcode::Floor:
      return true;
    default:
      return false;
  }
}

void runScalar(const std::vector<Instruction>& code, float* s)
{
  for (const Instruction& ins : code)
  {
    s[ins.out] = detail::applyScalar<float>(ins.op, s[ins.a], s[ins.b], s[ins.c]);
  }
}

constexpr std::size_t never = std::numeric_limits<std::size_t>::max();
constexpr std::uint32_t scalarBit = RowProgram::ScalarOperand;

// Comparison predicates (ordered, quiet: false on NaN).
constexpr int cmpGE = 0x1D;
constexpr int cmpGT = 0x1E;
constexpr int cmpLT = 0x11;

class Generator
{
public:
  Generator(const RowProgram& p, std::uint8_t varyingAxes, bool avx512)
    : p_(p)
    , avx512_(avx512)
    , width_(avx512 ? 16 : 8)
    , vectorBytes_(avx512 ? 64 : 32)
    , registerCount_(avx512 ? 30 : 14) // the top two are scratch
    , varyingAxes_(varyingAxes)
  {
  }

  JitFunction generate(std::size_t& codeSize)
  {
    asmjit::CodeHolder code;
    code.init(runtime().environment());
    x86::Assembler a(&code);
    as_ = &a;
    constants_ = a.newLabel();
    analyse();

    // Prologue: callee-saved registers hold the arguments (calls out clobber the others).
    a.push(x86::rbx);
    a.push(x86::rbp);
    a.push(x86::r12);
    a.push(x86::r13);
    a.push(x86::r14);
    a.push(x86::r15);
    a.sub(x86::rsp, 8); // 16-byte alignment at calls
    a.mov(x86::r13, x86::rdi);
    a.mov(x86::r12, x86::rsi);
    a.mov(x86::r14, x86::rdx);
    a.mov(x86::rbx, x86::rcx);
    a.mov(x86::r15, x86::r8);
    a.xor_(x86::ebp, x86::ebp); // byte offset of the current vector
    asmjit::Label loop = a.newLabel();
    a.bind(loop);
    regs_.assign(registerCount_, RegState{});
    regOfSlot_.assign(p_.chunkSlotCount, -1);
    for (std::size_t i = 0; i < p_.varying.size(); ++i)
    {
      emitInstruction(i);
    }
    // Outputs.
    for (std::size_t k = 0; k < p_.outputs.size(); ++k)
    {
      if (!p_.outputs[k].varying)
      {
        continue;
      }
      const std::uint32_t slot = p_.outputs[k].slot;
      x86::Vec v = scratch(0);
      if (regOfSlot_[slot] >= 0)
      {
        v = vec(regOfSlot_[slot]);
      }
      else
      {
        load(v, slot);
      }
      a.mov(x86::rax, x86::qword_ptr(x86::r14, static_cast<std::int32_t>(8 * k)));
      a.vmovups(x86::ptr(x86::rax, x86::rbp), v);
    }
    a.add(x86::rbp, vectorBytes_);
    a.dec(x86::r15);
    a.jnz(loop);
    a.vzeroupper();
    a.add(x86::rsp, 8);
    a.pop(x86::r15);
    a.pop(x86::r14);
    a.pop(x86::r13);
    a.pop(x86::r12);
    a.pop(x86::rbp);
    a.pop(x86::rbx);
    a.ret();

    // Constant vectors (64 bytes each, enough for either width).
    a.align(asmjit::AlignMode::kData, 64);
    a.bind(constants_);
    const std::uint32_t patterns[5] = { 0x80000000u, 0x7fffffffu, 0x3f800000u, 0xbf800000u, 0u };
    for (std::uint32_t bits : patterns)
    {
      for (int i = 0; i < 16; ++i)
      {
        a.embed(&bits, sizeof bits);
      }
    }
    JitFunction fn = nullptr;
    codeSize = code.codeSize();
    if (runtime().add(&fn, &code) != asmjit::kErrorOk || !fn)
    {
      throw std::runtime_error("JitEvaluator: code generation failed");
    }
    return fn;
  }

  // Bytes per slot of the home area; call-out operands use three extra slots after the chunk
  // slots.
  std::size_t homeFloats() const
  {
    return (static_cast<std::size_t>(p_.chunkSlotCount) + 3) * width_;
  }
  int width() const { return width_; }

private:
  enum Constant
  {
    SignMask,
    AbsMask,
    One,
    MinusOne,
    Zero
  };
  struct RegState
  {
    std::int64_t slot = -1;
    std::size_t nextUse = never;
    bool dirty = false;
  };
  enum class Source : std::uint8_t
  {
    Home,
    Axis,
    Broadcast
  };

  x86::Vec vec(int i) const { return avx512_ ? x86::Vec(x86::zmm(i)) : x86::Vec(x86::ymm(i)); }
  x86::Vec scratch(int k) const { return vec(registerCount_ + k); }
  x86::Mem constant(Constant c) const { return x86::ptr(constants_, 64 * static_cast<int>(c)); }
  x86::Mem home(std::uint32_t slot) const
  {
    return x86::ptr(x86::rbx, static_cast<std::int32_t>(slot * vectorBytes_));
  }
  x86::Mem scalar(std::uint32_t id) const
  {
    return x86::dword_ptr(x86::r12, static_cast<std::int32_t>(4 * id));
  }

  // Where each chunk slot's value comes from, and the next read of every operand and result.
  void analyse()
  {
    source_.assign(p_.chunkSlotCount, Source::Home);
    sourceIndex_.assign(p_.chunkSlotCount, 0);
    for (std::uint32_t a = 0; a < 4; ++a)
    {
      if (varyingAxes_ & (1u << a))
      {
        source_[p_.axisSlots[a]] = Source::Axis;
        sourceIndex_[p_.axisSlots[a]] = a;
      }
    }
    for (const auto* list : { &p_.broadcasts, &p_.fixedBroadcasts })
    {
      for (const auto& [scalarId, chunk] : *list)
      {
        source_[chunk] = Source::Broadcast;
        sourceIndex_[chunk] = scalarId;
      }
    }
    const std::size_t n = p_.varying.size();
    std::vector<std::size_t> nextRead(p_.chunkSlotCount, never);
    for (const RowProgram::Output& o : p_.outputs)
    {
      if (o.varying)
      {
        nextRead[o.slot] = n;
      }
    }
    operandNext_.assign(n, { never, never, never });
    resultNext_.assign(n, never);
    for (std::size_t i = n; i-- > 0;)
    {
      const Instruction& ins = p_.varying[i];
      resultNext_[i] = nextRead[ins.out];
      nextRead[ins.out] = never;
      const std::uint32_t operands[3] = { ins.a, ins.b, ins.c };
      const int arity = detail::arity(ins.op);
      for (int k = 0; k < arity; ++k)
      {
        if (!(operands[k] & scalarBit))
        {
          operandNext_[i][k] = nextRead[operands[k]];
        }
      }
      for (int k = 0; k < arity; ++k)
      {
        if (!(operands[k] & scalarBit))
        {
          nextRead[operands[k]] = i;
        }
      }
    }
  }

  void load(const x86::Vec& v, std::uint32_t slot)
  {
    x86::Assembler& a = *as_;
    switch (source_[slot])
    {
      case Source::Home:
        a.vmovups(v, home(slot));
        break;
      case Source::Axis:
        a.mov(
          x86::rax, x86::qword_ptr(x86::r13, static_cast<std::int32_t>(8 * sourceIndex_[slot])));
        a.vmovups(v, x86::ptr(x86::rax, x86::rbp));
        break;
      case Source::Broadcast:
        a.vbroadcastss(v, scalar(sourceIndex_[slot]));
        break;
    }
  }

  void release(int r)
  {
    if (regs_[r].slot >= 0)
    {
      regOfSlot_[static_cast<std::size_t>(regs_[r].slot)] = -1;
    }
    regs_[r] = RegState{};
  }

  // A register for a new value: a free one, else the one whose value is needed last (stored to
  // its home first when it is still needed and memory does not hold it).
  int allocate(const bool* locked)
  {
    int best = -1;
    for (int r = 0; r < registerCount_; ++r)
    {
      if (locked[r])
      {
        continue;
      }
      if (regs_[r].slot < 0)
      {
        return r;
      }
      if (best < 0 || regs_[r].nextUse > regs_[best].nextUse)
      {
        best = r;
      }
    }
    RegState& s = regs_[best];
    if (s.dirty && s.nextUse != never)
    {
      as_->vmovups(home(static_cast<std::uint32_t>(s.slot)), vec(best));
    }
    release(best);
    return best;
  }

  int ensure(std::uint32_t slot, bool* locked)
  {
    int r = regOfSlot_[slot];
    if (r < 0)
    {
      r = allocate(locked);
      load(vec(r), slot);
      regs_[r].slot = slot;
      regs_[r].dirty = false;
      regOfSlot_[slot] = r;
    }
    locked[r] = true;
    return r;
  }

  void emitCall(std::size_t i)
  {
    x86::Assembler& a = *as_;
    const Instruction& ins = p_.varying[i];
    // Every vector register is caller-saved: store what is still needed, forget the rest.
    for (int r = 0; r < registerCount_; ++r)
    {
      if (regs_[r].slot >= 0 && regs_[r].dirty && regs_[r].nextUse != never)
      {
        a.vmovups(home(static_cast<std::uint32_t>(regs_[r].slot)), vec(r));
      }
      release(r);
    }
    const std::uint32_t operands[3] = { ins.a, ins.b, ins.c };
    const int arity = detail::arity(ins.op);
    x86::Gp args[3] = { x86::rdx, x86::rcx, x86::r8 };
    for (int k = 0; k < 3; ++k)
    {
      const std::uint32_t v = operands[k < arity ? k : 0];
      x86::Mem m;
      if (v & scalarBit)
      {
        a.vbroadcastss(scratch(0), scalar(v & ~scalarBit));
        m = home(p_.chunkSlotCount + k);
        a.vmovups(m, scratch(0));
      }
      else if (source_[v] != Source::Home)
      {
        load(scratch(0), v);
        m = home(p_.chunkSlotCount + k);
        a.vmovups(m, scratch(0));
      }
      else
      {
        m = home(v);
      }
      a.lea(args[k], m);
    }
    a.mov(x86::edi, static_cast<std::uint32_t>(ins.op));
    a.lea(x86::rsi, home(ins.out));
    a.mov(x86::r9, width_);
    a.vzeroupper();
    a.mov(x86::rax, reinterpret_cast<std::uint64_t>(&callKernel));
    a.call(x86::rax);
    // The result is in its home (not in a register).
  }

  void emitInstruction(std::size_t i)
  {
    x86::Assembler& a = *as_;
    const Instruction& ins = p_.varying[i];
    if (!native(ins.op))
    {
      emitCall(i);
      return;
    }
    const int arity = detail::arity(ins.op);
    const std::uint32_t operands[3] = { ins.a, ins.b, ins.c };
    bool locked[32] = {};
    int reg[3] = { -1, -1, -1 };
    int scalarOperand = -1;
    for (int k = 0; k < arity; ++k)
    {
      if (operands[k] & scalarBit)
      {
        scalarOperand = k;
        continue;
      }
      reg[k] = ensure(operands[k], locked);
    }
    for (int k = 0; k < arity; ++k)
    {
      if (reg[k] >= 0)
      {
        regs_[reg[k]].nextUse = operandNext_[i][k];
      }
    }
    // Operands read for the last time free their registers (the result may take one).
    for (int k = 0; k < arity; ++k)
    {
      if (reg[k] >= 0 && regs_[reg[k]].nextUse == never && regs_[reg[k]].slot >= 0)
      {
        locked[reg[k]] = false;
        release(reg[k]);
      }
    }
    if (regOfSlot_[ins.out] >= 0)
    {
      release(regOfSlot_[ins.out]); // a dead earlier value of the same slot
    }
    const int out = allocate(locked);
    const x86::Vec d = vec(out);
    x86::Vec A, B, C;
    if (reg[0] >= 0)
      A = vec(reg[0]);
    if (arity > 1 && reg[1] >= 0)
      B = vec(reg[1]);
    if (arity > 2)
      C = vec(reg[2]);

    if (scalarOperand >= 0)
    {
      const x86::Mem s = scalar(operands[scalarOperand] & ~scalarBit);
      const bool first = scalarOperand == 0;
      const x86::Vec V = first ? B : A;
      // AVX-512 reads a broadcast scalar as the second source directly where the operation
      // allows it (add and mul commute; min(s, v) = vminps(v, s); max(s, v) = vmaxps(v, s)).
      const x86::Mem sb = s._1to16();
      bool done = false;
      if (avx512_)
      {
        done = true;
        switch (ins.op)
        {
          case Opcode::Add:
            a.vaddps(d, V, sb);
            break;
          case Opcode::Mul:
            a.vmulps(d, V, sb);
            break;
          case Opcode::Sub:
            if (first)
              done = false;
            else
              a.vsubps(d, V, sb);
            break;
          case Opcode::Div:
            if (first)
              done = false;
            else
              a.vdivps(d, V, sb);
            break;
          case Opcode::Min:
            if (first)
              a.vminps(d, V, sb);
            else
              done = false;
            break;
          case Opcode::Max:
            if (first)
              a.vmaxps(d, V, sb);
            else
              done = false;
            break;
          default:
            done = false;
            break;
        }
      }
      if (!done)
      {
        const x86::Vec S = scratch(0);
        a.vbroadcastss(S, s);
        if (first)
          A = S;
        else
          B = S;
      }
      else
      {
        finish(i, out);
        return;
      }
    }

    switch (ins.op)
    {
      case Opcode::Neg:
        if (avx512_)
          a.vpxord(d, A, constant(SignMask));
        else
          a.vxorps(d, A, constant(SignMask));
        break;
      case Opcode::Abs:
        if (avx512_)
          a.vpandd(d, A, constant(AbsMask));
        else
          a.vandps(d, A, constant(AbsMask));
        break;
      case Opcode::Sqrt:
        a.vsqrtps(d, A);
        break;
      case Opcode::Square:
        a.vmulps(d, A, A);
        break;
      case Opcode::Add:
        a.vaddps(d, A, B);
        break;
      case Opcode::Sub:
        a.vsubps(d, A, B);
        break;
      case Opcode::Mul:
        a.vmulps(d, A, B);
        break;
      case Opcode::Div:
        a.vdivps(d, A, B);
        break;
      case Opcode::Min:
        // minOp(a, b) = b < a ? b : a = vminps(b, a) (the second source on NaN and equal values).
        a.vminps(d, B, A);
        break;
      case Opcode::Max:
        // maxOp(a, b) = a < b ? b : a = vmaxps(b, a).
        a.vmaxps(d, B, A);
        break;
      case Opcode::Select:
        // a >= 0 ? b : c; NaN takes c.
        if (avx512_)
        {
          a.vcmpps(x86::k1, A, constant(Zero), cmpGE);
          a.k(x86::k1).vblendmps(d, C, B);
        }
        else
        {
          a.vcmpps(scratch(0), A, constant(Zero), cmpGE);
          a.vblendvps(d, C, B, scratch(0));
        }
        break;
      case Opcode::Sign:
        if (avx512_)
        {
          a.vcmpps(x86::k1, A, constant(Zero), cmpGT);
          a.vcmpps(x86::k2, A, constant(Zero), cmpLT);
          a.vmovups(d, constant(Zero));
          a.k(x86::k1).vmovups(d, constant(One));
          a.k(x86::k2).vmovups(d, constant(MinusOne));
        }
        else
        {
          a.vcmpps(scratch(0), A, constant(Zero), cmpGT);
          a.vandps(scratch(0), scratch(0), constant(One));
          a.vcmpps(scratch(1), A, constant(Zero), cmpLT);
          a.vandps(scratch(1), scratch(1), constant(MinusOne));
          a.vorps(d, scratch(0), scratch(1));
        }
        break;
      case Opcode::Floor:
        if (avx512_)
          a.vrndscaleps(d, A, 0x09); // round down, no precision exception
        else
          a.vroundps(d, A, 0x09);
        break;
      default:
        break;
    }
    finish(i, out);
  }

  void finish(std::size_t i, int out)
  {
    const Instruction& ins = p_.varying[i];
    regs_[out] = { ins.out, resultNext_[i], true };
    regOfSlot_[ins.out] = out;
    if (resultNext_[i] == never)
    {
      release(out); // never read (not expected from the tape)
    }
  }

  const RowProgram& p_;
  bool avx512_;
  int width_;
  int vectorBytes_;
  int registerCount_;
  std::uint8_t varyingAxes_;
  x86::Assembler* as_ = nullptr;
  asmjit::Label constants_;
  std::vector<Source> source_;
  std::vector<std::uint32_t> sourceIndex_;
  std::vector<std::array<std::size_t, 3>> operandNext_;
  std::vector<std::size_t> resultNext_;
  std::vector<RegState> regs_;
  std::vector<int> regOfSlot_;
};

bool hostHasAvx512()
{
  const auto& cpu = asmjit::CpuInfo::host();
  return cpu.hasFeature(asmjit::CpuFeatures::X86::kAVX512_F);
}

// A compiled row program and its working memory.
struct Compiled
{
  RowProgram row;
  std::uint8_t varyingAxes = 0;
  JitFunction fn = nullptr;
  std::size_t codeSize = 0;
  int width = 8;
  bool anyVarying = false;
  std::vector<float> scalars;
  std::vector<float> homeStorage;
  float* home = nullptr;

  Compiled() = default;
  Compiled(const Compiled&) = delete;
  Compiled& operator=(const Compiled&) = delete;
  ~Compiled()
  {
    if (fn)
    {
      runtime().release(fn);
    }
  }

  void build(const Tape& tape, std::uint8_t axes, bool avx512)
  {
    varyingAxes = axes;
    row = tape.rowProgram(axes);
    anyVarying = std::any_of(row.outputs.begin(), row.outputs.end(),
      [](const RowProgram::Output& o) { return o.varying; });
    Generator g(row, axes, avx512);
    width = g.width();
    homeStorage.assign(g.homeFloats() + 16, 0.0f);
    auto address = reinterpret_cast<std::uintptr_t>(homeStorage.data());
    home = homeStorage.data() + ((64 - address % 64) % 64) / sizeof(float);
    if (anyVarying)
    {
      fn = g.generate(codeSize);
    }
  }

  void setParameters(const Tape& tape, const std::vector<double>& parameters)
  {
    scalars.assign(row.scalarSlotCount, 0.0f);
    for (std::uint32_t i = 0; i < tape.parameterCount(); ++i)
    {
      scalars[tape.parameterBase() + i] = static_cast<float>(parameters[i]);
    }
    for (std::size_t i = 0; i < tape.constants().size(); ++i)
    {
      scalars[tape.constantBase() + i] = static_cast<float>(tape.constants()[i]);
    }
    runScalar(row.uniform, scalars.data());
  }
};
} // namespace

struct JitEvaluator::Impl
{
  TapePtr tape;
  std::vector<double> parameters;
  bool avx512 = false;
  Compiled rowX;
  std::unique_ptr<Compiled> full; // eval(), on first use
  // evalRowX: the x coordinates of the last row (padded to whole vectors).
  std::vector<float> xs;
  double x0 = 0, dx = 0;
  std::int64_t first = -1;
  std::size_t count = 0;
  std::vector<std::vector<float>> outBuffers;
  std::vector<float*> outPointers;
  std::vector<float> tailInputs;
};

bool JitEvaluator::available()
{
  // AVX2, and executable memory (a hardened kernel may refuse it): compile a trivial tape once.
  static const bool ok = []
  {
    if (!asmjit::CpuInfo::host().hasFeature(asmjit::CpuFeatures::X86::kAVX2))
    {
      return false;
    }
    try
    {
      Compiled probe;
      probe.build(*Tape::compile(Expr::x() + 1.0), 1u, false);
      return probe.fn != nullptr;
    }
    catch (const std::exception&)
    {
      return false;
    }
  }();
  return ok;
}

JitEvaluator::JitEvaluator(
  TapePtr tape, const std::vector<double>& parameters, const JitOptions& options)
  : impl_(std::make_unique<Impl>())
{
  if (!available())
  {
    throw std::runtime_error("JitEvaluator: this CPU has no AVX2");
  }
  impl_->tape = std::move(tape);
  impl_->avx512 = options.allowAvx512 && hostHasAvx512();
  impl_->rowX.build(*impl_->tape, 1u << static_cast<int>(Axis::X), impl_->avx512);
  setParameters(parameters);
}

JitEvaluator::~JitEvaluator() = default;

const TapePtr& JitEvaluator::tape() const
{
  return impl_->tape;
}

int JitEvaluator::vectorWidth() const
{
  return impl_->rowX.width;
}

std::size_t JitEvaluator::codeSize() const
{
  return impl_->rowX.codeSize;
}

void JitEvaluator::setParameters(const std::vector<double>& parameters)
{
  const Tape& tape = *impl_->tape;
  if (parameters.size() < tape.parameterCount())
  {
    throw std::invalid_argument("the model has " + std::to_string(tape.parameterCount()) +
      " parameter(s) but " + std::to_string(parameters.size()) + " value(s) were given");
  }
  impl_->parameters.assign(parameters.begin(), parameters.begin() + tape.parameterCount());
  impl_->rowX.setParameters(tape, impl_->parameters);
  if (impl_->full)
  {
    impl_->full->setParameters(tape, impl_->parameters);
  }
}

void JitEvaluator::eval(
  const float* x, const float* y, const float* z, const float* t, float* out, std::size_t n)
{
  Impl& m = *impl_;
  const Tape& tape = *m.tape;
  const float* inputs[4] = { x, y, z, t };
  for (int a = 0; a < 4; ++a)
  {
    if (!inputs[a] && (tape.axesUsed() & (1u << a)))
    {
      throw std::invalid_argument(std::string("JitEvaluator::eval: the model uses coordinate ") +
        axisName(static_cast<Axis>(a)) + " but no values were given for it");
    }
  }
  if (!m.full)
  {
    m.full = std::make_unique<Compiled>();
    m.full->build(tape, tape.axesUsed(), m.avx512);
    m.full->setParameters(tape, m.parameters);
  }
  Compiled& c = *m.full;
  const RowProgram::Output& o = c.row.outputs[0];
  if (!o.varying)
  {
    std::fill_n(out, n, c.scalars[o.slot]);
    return;
  }
  const std::size_t w = static_cast<std::size_t>(c.width);
  const std::size_t outputCount = c.row.outputs.size();
  m.outBuffers.resize(outputCount);
  m.outPointers.resize(outputCount);
  const std::size_t whole = n / w;
  for (std::size_t k = 0; k < outputCount; ++k)
  {
    m.outBuffers[k].resize(std::max<std::size_t>(whole, 1) * w);
    m.outPointers[k] = k == 0 ? out : m.outBuffers[k].data();
  }
  if (whole > 0)
  {
    c.fn(inputs, c.scalars.data(), m.outPointers.data(), c.home, whole);
  }
  const std::size_t rest = n - whole * w;
  if (rest > 0)
  {
    // The last partial vector, through padded copies.
    m.tailInputs.assign(5 * w, 0.0f);
    const float* tail[4] = {};
    for (int a = 0; a < 4; ++a)
    {
      if (inputs[a])
      {
        std::copy_n(inputs[a] + whole * w, rest, m.tailInputs.data() + a * w);
        tail[a] = m.tailInputs.data() + a * w;
      }
    }
    for (std::size_t k = 0; k < outputCount; ++k)
    {
      m.outPointers[k] = m.outBuffers[k].data();
    }
    c.fn(tail, c.scalars.data(), m.outPointers.data(), c.home, 1);
    std::copy_n(m.outBuffers[0].data(), rest, out + whole * w);
  }
}

void JitEvaluator::evalRowX(
  double x0, double dx, std::int64_t first, double y, double z, double t, float* out, std::size_t n)
{
  evalRowX(x0, dx, first, y, z, t, &out, 1, n);
}

void JitEvaluator::evalRowX(double x0, double dx, std::int64_t first, double y, double z, double t,
  float* const* outputs, std::size_t outputCount, std::size_t n)
{
  Impl& m = *impl_;
  Compiled& c = m.rowX;
  if (outputCount > c.row.outputs.size())
  {
    throw std::invalid_argument("JitEvaluator::evalRowX: the tape has " +
      std::to_string(c.row.outputs.size()) + " output(s), " + std::to_string(outputCount) +
      " asked");
  }
  float* s = c.scalars.data();
  s[0] = static_cast<float>(x0 + static_cast<double>(first) * dx);
  s[1] = static_cast<float>(y);
  s[2] = static_cast<float>(z);
  s[3] = static_cast<float>(t);
  runScalar(c.row.uniform, s);
  bool anyVarying = false;
  for (std::size_t k = 0; k < outputCount; ++k)
  {
    if (!c.row.outputs[k].varying)
    {
      std::fill_n(outputs[k], n, s[c.row.outputs[k].slot]);
    }
    anyVarying = anyVarying || c.row.outputs[k].varying;
  }
  if (!anyVarying || n == 0)
  {
    return;
  }
  const std::size_t w = static_cast<std::size_t>(c.width);
  const std::size_t nvec = (n + w - 1) / w;
  if (!(m.x0 == x0 && m.dx == dx && m.first == first && m.count == n))
  {
    // Coordinates in double, as every other evaluator receives them (the padding too).
    m.xs.resize(nvec * w);
    for (std::size_t i = 0; i < nvec * w; ++i)
    {
      m.xs[i] =
        static_cast<float>(x0 + static_cast<double>(first + static_cast<std::int64_t>(i)) * dx);
    }
    m.x0 = x0;
    m.dx = dx;
    m.first = first;
    m.count = n;
  }
  const float* axes[4] = { m.xs.data(), nullptr, nullptr, nullptr };
  const std::size_t total = c.row.outputs.size();
  m.outBuffers.resize(total);
  m.outPointers.resize(total);
  const bool direct = n % w == 0;
  for (std::size_t k = 0; k < total; ++k)
  {
    if (direct && k < outputCount)
    {
      m.outPointers[k] = outputs[k];
    }
    else
    {
      m.outBuffers[k].resize(nvec * w);
      m.outPointers[k] = m.outBuffers[k].data();
    }
  }
  c.fn(axes, s, m.outPointers.data(), c.home, nvec);
  if (!direct)
  {
    for (std::size_t k = 0; k < outputCount; ++k)
    {
      if (c.row.outputs[k].varying)
      {
        std::copy_n(m.outBuffers[k].data(), n, outputs[k]);
      }
    }
  }
}

RowEvaluatorFactory jitRowEvaluatorFactory(const JitOptions& options)
{
  if (!JitEvaluator::available())
  {
    return {};
  }
  return [options](const TapePtr& tape, const std::vector<double>& parameters)
  {
    return std::unique_ptr<RowEvaluator>(new JitEvaluator(tape, parameters, options));
  };
}

} // namespace ictk::frep
