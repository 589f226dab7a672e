// SPDX-License-Identifier: BSD-3-Clause
// The .vm importer (Fidget's SSA benchmark format): hand-computed values, diagnostics at the right
// line and column, no crash on mangled input, and prospero.vm against an independent interpreter.
#include "FRep/Evaluators.h"
#include "Lang/ModelFile.h"
#include "Lang/VmReader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>

using namespace ictk;
using lang::readVm;

namespace
{
double evalAt(const lang::VmModel& m, double x, double y, double z)
{
  frep::PointEvaluator e(frep::Tape::compile(m.function));
  return e.eval(x, y, z);
}

struct Expected
{
  int line;
  int column;
  std::string message; // a substring of the message
};

Expected firstError(const std::string& text)
{
  try
  {
    readVm(text, "m.vm");
  }
  catch (const lang::ParseError& e)
  {
    const lang::Diagnostic& d = e.diagnostics().at(0);
    EXPECT_EQ(d.where.file, "m.vm");
    return { d.where.line, d.where.column, d.message };
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return { -1, -1, "" };
}

#define EXPECT_VM_ERROR(text, wantLine, wantColumn, fragment)                                      \
  do                                                                                               \
  {                                                                                                \
    const Expected got = firstError(text);                                                         \
    EXPECT_EQ(got.line, wantLine) << got.message;                                                  \
    EXPECT_EQ(got.column, wantColumn) << got.message;                                              \
    EXPECT_NE(got.message.find(fragment), std::string::npos) << got.message;                       \
  } while (false)

std::filesystem::path benchModels()
{
  if (const char* env = std::getenv("ICTK_BENCH_MODELS"))
  {
    return env;
  }
  return ICTK_BENCH_MODELS_DIR;
}

// An independent reading of the format, in double: name -> value, one line at a time.
double interpret(const std::string& path, double x, double y, double z)
{
  std::ifstream in(path);
  std::map<std::string, double> v;
  std::string line, last;
  while (std::getline(in, line))
  {
    std::istringstream is(line);
    std::string id, op, a, b;
    if (!(is >> id) || id[0] == '#' || !(is >> op))
    {
      continue;
    }
    is >> a >> b;
    double r = 0;
    if (op == "const")
      r = std::strtod(a.c_str(), nullptr);
    else if (op == "var-x")
      r = x;
    else if (op == "var-y")
      r = y;
    else if (op == "var-z")
      r = z;
    else if (op == "add")
      r = v.at(a) + v.at(b);
    else if (op == "sub")
      r = v.at(a) - v.at(b);
    else if (op == "mul")
      r = v.at(a) * v.at(b);
    else if (op == "div")
      r = v.at(a) / v.at(b);
    else if (op == "min")
      r = std::fmin(v.at(a), v.at(b));
    else if (op == "max")
      r = std::fmax(v.at(a), v.at(b));
    else if (op == "neg")
      r = -v.at(a);
    else if (op == "square")
      r = v.at(a) * v.at(a);
    else if (op == "sqrt")
      r = std::sqrt(v.at(a));
    else if (op == "abs")
      r = std::fabs(v.at(a));
    else if (op == "exp")
      r = std::exp(v.at(a));
    else if (op == "ln")
      r = std::log(v.at(a));
    else if (op == "sin")
      r = std::sin(v.at(a));
    else if (op == "cos")
      r = std::cos(v.at(a));
    else
      throw std::runtime_error("unknown opcode " + op);
    v[id] = r;
    last = id;
  }
  return v.at(last);
}
} // namespace

TEST(VmReader, CircleIsNegated)
{
  const std::string text = "# unit circle, negative inside\n"
                           "_0 var-x\n"
                           "_1 var-y\n"
                           "\n"
                           "_2 square _0\n"
                           "_3 square _1\n"
                           "_4 add _2 _3\n"
                           "_5 const 1\n"
                           "_6 sub _4 _5\n";
  const lang::VmModel m = readVm(text, "circle.vm");
  EXPECT_EQ(m.instructionCount, 7u);
  EXPECT_EQ(m.axesUsed, 3u);
  EXPECT_EQ(evalAt(m, 0.5, 0.5, 0), 0.5); // raw 0.25 + 0.25 - 1 = -0.5
  EXPECT_EQ(evalAt(m, 2, 0, 7), -3.0);    // raw 4 - 1 = 3
  EXPECT_EQ(evalAt(m, 0, 0, 0), 1.0);     // centre
  EXPECT_EQ(frep::toString(m.raw), frep::toString(-m.function));
}

TEST(VmReader, EveryOpcode)
{
  // At (2, 3, 0.5), by hand.
  const std::string text = "x var-x\n"
                           "y var-y\n"
                           "z var-z\n"
                           "a add x y\n"  // 5
                           "b sub a z\n"  // 4.5
                           "c mul b x\n"  // 9
                           "d div c y\n"  // 3
                           "e neg d\n"    // -3
                           "f abs e\n"    // 3
                           "g square f\n" // 9
                           "h sqrt g\n"   // 3
                           "i min h z\n"  // 0.5
                           "j max i e\n"  // 0.5
                           "k exp z\n"    // e^0.5
                           "l ln k\n"     // 0.5
                           "m sin l\n"    // sin 0.5
                           "n cos l\n"    // cos 0.5
                           "o square m\n" //
                           "p square n\n" //
                           "q add o p\n"  // 1
                           "r add q j\n"  // 1.5
                           "s\tadd  r l"; // 2, tabs and double spaces, no final newline
  const lang::VmModel m = readVm(text);
  EXPECT_EQ(m.instructionCount, 22u);
  EXPECT_EQ(m.axesUsed, 7u);
  EXPECT_NEAR(evalAt(m, 2, 3, 0.5), -2.0, 1e-14);
}

TEST(VmReader, WindowsLineEndingsAndArbitraryNames)
{
  const lang::VmModel m = readVm("y var-y\r\nx var-x\r\n\r\nmxy max x y\r\n");
  EXPECT_EQ(evalAt(m, -0.25, -0.5, 0), 0.25);
  EXPECT_EQ(m.axesUsed, 3u);
}

TEST(VmReader, ErrorsAtLineAndColumn)
{
  EXPECT_VM_ERROR("_0 var-x\n_1 foo _0\n", 2, 4, "unknown opcode 'foo'");
  EXPECT_VM_ERROR("_0 var-x\n_1 add _0\n", 2, 10, "'add' expects 2 operand(s), got 1");
  EXPECT_VM_ERROR("_0 var-x\n_1 neg _0 _0\n", 2, 11, "unexpected '_0'");
  EXPECT_VM_ERROR("_0 const abc\n", 1, 10, "'abc' is not a number");
  EXPECT_VM_ERROR("_0 const 1.5x\n", 1, 10, "is not a number");
  EXPECT_VM_ERROR("_0 const 1e999\n", 1, 10, "out of range");
  EXPECT_VM_ERROR("  \t_0 const nan\n", 1, 13, "NaN");
  EXPECT_VM_ERROR("_0 const\n", 1, 9, "'const' expects a number, got 0");
  EXPECT_VM_ERROR("_0 var-x\n_1 add _0 _9\n", 2, 11, "'_9' is not defined");
  EXPECT_VM_ERROR("_1 neg _0\n_0 var-x\n", 1, 8, "'_0' is not defined");
  EXPECT_VM_ERROR("_0 var-x\n# comment\n_0 var-y\n", 3, 1, "already defined at line 1");
  EXPECT_VM_ERROR("_0 var-x\n_0\n", 2, 3, "expected an opcode");
  EXPECT_VM_ERROR("_0 var-x extra\n", 1, 10, "unexpected 'extra'");
  EXPECT_VM_ERROR("", 0, 0, "no instructions");
  EXPECT_VM_ERROR("# only a comment\n\n", 0, 0, "no instructions");
}

TEST(VmReader, SeveralErrorsWithoutCascades)
{
  try
  {
    // Line 1 is wrong; lines 2-3 use it and must not report again; line 4 has its own error.
    readVm("_0 bad\n_1 neg _0\n_2 add _1 _0\n_3 sqrt _77\n", "m.vm");
    FAIL() << "no error";
  }
  catch (const lang::ParseError& e)
  {
    ASSERT_EQ(e.diagnostics().size(), 2u);
    EXPECT_EQ(e.diagnostics()[0].where.line, 1);
    EXPECT_EQ(e.diagnostics()[1].where.line, 4);
    EXPECT_EQ(e.diagnostics()[1].where.column, 9);
    const std::string what = e.what();
    EXPECT_NE(what.find("m.vm:1:4: error: unknown opcode 'bad'"), std::string::npos) << what;
    EXPECT_NE(what.find("_3 sqrt _77\n        ^"), std::string::npos) << what;
  }
}

TEST(VmReader, LimitsAreErrors)
{
  lang::Limits limits;
  limits.maxExpressionNodes = 3;
  EXPECT_THROW(readVm("a var-x\nb var-y\nc add a b\nd neg c\n", "", limits), lang::ParseError);
  limits = {};
  limits.maxFileBytes = 10;
  EXPECT_THROW(readVm("a var-x\nb var-y\nc add a b\n", "", limits), lang::ParseError);
}

TEST(VmReader, MangledInputNeverCrashes)
{
  const std::string valid = "_0 var-x\n_1 const 2.5\n_2 mul _0 _1\n_3 square _2\n_4 sub _3 _1\n";
  const std::string alphabet = "_0123456789abcdefxyz- \t\r\n#.eE+";
  std::mt19937 rng(7);
  int parsed = 0;
  for (int round = 0; round < 3000; ++round)
  {
    std::string text = valid;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits; ++k)
    {
      const std::size_t at = rng() % (text.size() + 1);
      switch (rng() % 3)
      {
        case 0:
          text.insert(at, 1, alphabet[rng() % alphabet.size()]);
          break;
        case 1:
          if (at < text.size())
            text.erase(at, 1);
          break;
        default:
          if (at < text.size())
            text[at] = static_cast<char>(rng() % 256);
      }
    }
    try
    {
      const lang::VmModel m = readVm(text, "fuzz.vm");
      (void)evalAt(m, 0.5, -0.5, 0.25);
      ++parsed;
    }
    catch (const lang::ParseError& e)
    {
      ASSERT_FALSE(e.diagnostics().empty());
      for (const lang::Diagnostic& d : e.diagnostics())
      {
        ASSERT_GE(d.where.line, 0);
        ASSERT_GE(d.where.column, 0);
      }
    }
  }
  EXPECT_GT(parsed, 0);
}

TEST(VmReader, LoadModelFile)
{
  const auto dir = std::filesystem::temp_directory_path() / "ictk-vm-test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "quarter.vm").string();
  {
    std::ofstream out(path);
    out << "# a quarter plane\ny var-y\nx var-x\nmxy max x y\n";
  }
  ASSERT_TRUE(lang::isModelFile(path));
  const lang::ModelFile file = lang::loadModelFile(path);
  EXPECT_EQ(file.name, "quarter");
  EXPECT_EQ(file.model.geometry().domain(), frep::Domain::XY);
  frep::PointEvaluator e(frep::Tape::compile(file.model.geometry().function()));
  EXPECT_EQ(e.eval(-1, -2), 1.0);
  EXPECT_EQ(e.eval(1, -2), -1.0);
  EXPECT_THROW(lang::saveModelFile(file, path), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(VmReader, ProsperoMatchesAnIndependentInterpreter)
{
  const std::filesystem::path file = benchModels() / "prospero.vm";
  if (!std::filesystem::exists(file))
  {
    GTEST_SKIP() << file << " is absent (set ICTK_BENCH_MODELS to Fidget's models folder)";
  }
  const lang::VmModel m = lang::readVmFile(file.string());
  EXPECT_EQ(m.instructionCount, 7866u);
  EXPECT_EQ(m.axesUsed, 3u);
  // Every instruction is a node, except repeated constants, which hash-consing merges.
  const std::size_t nodes = m.raw.nodeCount();
  EXPECT_LE(nodes, 7866u);
  EXPECT_GE(nodes, 7866u * 8 / 10);
  EXPECT_EQ(m.function.nodeCount(), nodes + 1); // the final negation
  const double points[][2] = { { 0, 0 }, { -0.5, 0.7 }, { 0.31, -0.62 }, { 0.9, 0.9 },
    { -0.777, -0.123 }, { 0.05, 0.45 } };
  int inside = 0;
  for (const auto& p : points)
  {
    const double want = -interpret(file.string(), p[0], p[1], 0);
    EXPECT_EQ(evalAt(m, p[0], p[1], 0), want) << "at " << p[0] << ", " << p[1];
    inside += want >= 0;
  }
  EXPECT_LT(inside, 6); // not a constant field
}
