// SPDX-License-Identifier: BSD-3-Clause
// Issue 15, the finite-element side: per-element materials binned in ln E, the compression case
// between frictionless platens solved by CalculiX against the Voigt and Reuss bounds (a
// homogeneous box, two layers in series and in parallel, a random modulus), the .frd reader
// against hand-written files and ccx's own output, von Mises of hand-known tensors. The solver
// tests fail, not skip, without ccx: Scripts/setup installs calculix-ccx.

#include "Mesh/Calculix.h"
#include "Mesh/Frd.h"
#include "Mesh/Quality.h"
#include "Mesh/Structured.h"
#include "Mesh/TetAttributes.h"
#include "Mesh/Writers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <sstream>

using namespace ictk;
using ::testing::HasSubstr;

namespace
{

namespace fs = std::filesystem;

/// A fresh folder under the temporary directory, removed with the object.
struct Scratch
{
  fs::path dir;
  explicit Scratch(const std::string& name)
  {
    std::random_device random;
    dir = fs::temp_directory_path() / ("ictk-" + name + "-" + std::to_string(random()));
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
  std::string operator/(const std::string& file) const { return (dir / file).string(); }
};

frep::Point3 centroid(const mesh::TetMesh& m, std::size_t t)
{
  frep::Point3 c{ 0, 0, 0 };
  for (auto i : m.tetrahedra[t])
  {
    for (int a = 0; a < 3; ++a)
    {
      c[std::size_t(a)] += m.points[i][std::size_t(a)] / 4;
    }
  }
  return c;
}

double volumeOf(const mesh::TetMesh& m, std::size_t t)
{
  const auto& k = m.tetrahedra[t];
  return mesh::tetShape(m.points[k[0]], m.points[k[1]], m.points[k[2]], m.points[k[3]]).volume;
}

/// A Kuhn mesh of the box as one cell "specimen", E per tetrahedron from `modulus`, nu = 0.3.
mesh::TetMesh specimen(const frep::Box3& box, const std::array<int, 3>& divisions,
  const std::function<double(const frep::Point3&)>& modulus, double poisson = 0.3)
{
  mesh::TetMesh m = mesh::kuhnTetMesh(box, divisions);
  const std::size_t n = m.tetrahedra.size();
  m.cells.assign(n, 0);
  m.materials.assign(n, 1);
  m.materialNames = { "specimen" };
  mesh::TetArray e{ "youngs_modulus", 1, {} }, nu{ "poisson_ratio", 1, {} };
  for (std::size_t t = 0; t < n; ++t)
  {
    e.values.push_back(modulus(centroid(m, t)));
    nu.values.push_back(poisson);
  }
  m.cellData = { e, nu };
  m.size = (box.hi[0] - box.lo[0]) / divisions[0];
  return m;
}

/// The written modulus of every tetrahedron.
std::vector<double> writtenModuli(const mesh::TetMesh& m, const std::vector<mesh::DeckMaterial>& d)
{
  std::vector<double> e(m.tetrahedra.size(), std::nan(""));
  for (const auto& material : d)
  {
    for (auto t : material.tetrahedra)
    {
      e[t] = material.youngsModulus;
    }
  }
  return e;
}

std::string readText(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what)
{
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
  {
    ++n;
  }
  return n;
}

mesh::CalculixOptions ccx()
{
  mesh::CalculixOptions o;
  o.executable = ICTK_CCX; // empty when CMake found no ccx: runCalculix then throws
  return o;
}

} // namespace

// --- binning --------------------------------------------------------------------------------

TEST(CalculixDeck, ModuliInKnownBins)
{
  // E = 1000 for k = t mod 7 = 0, else 1000 exp(w (k + 1/2)): seven bins counted from 1000, one
  // value each, at the centres of bins 2 to 7.
  const double w = 0.01;
  std::size_t t = 0;
  auto modulus = [&](std::size_t k)
  {
    return k == 0 ? 1000 : 1000 * std::exp(w * (double(k) + 0.5));
  };
  mesh::TetMesh m = specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 2, 2, 2 },
    [&](const frep::Point3&) { return modulus(t++ % 7); });
  const auto d = mesh::deckMaterials(m, w);
  ASSERT_EQ(d.size(), 7u);
  std::set<std::string> names;
  for (std::size_t k = 0; k < d.size(); ++k)
  {
    EXPECT_EQ(d[k].bin, int(k + 1));
    EXPECT_EQ(d[k].setName, "specimen_E" + std::to_string(k + 1));
    EXPECT_NEAR(d[k].youngsModulus, modulus(k), 1e-9);
    EXPECT_NEAR(d[k].poissonRatio, 0.3, 1e-15);
    EXPECT_TRUE(std::isnan(d[k].density));
    names.insert(d[k].setName);
  }
  EXPECT_EQ(names.size(), 7u);
  // Every element once, in the deck as its own bin's *ELSET.
  Scratch s("bins");
  mesh::writeAbaqus(m, s / "bins.inp");
  const std::string deck = readText(s / "bins.inp");
  EXPECT_EQ(count(deck, "*MATERIAL"), 7u);
  EXPECT_EQ(count(deck, "*ELSET, ELSET=specimen_E"), 7u);
  EXPECT_EQ(count(deck, "*SOLID SECTION"), 7u);
  EXPECT_THAT(deck, HasSubstr("*SOLID SECTION, ELSET=specimen_E7, MATERIAL=specimen_E7\n"));
  EXPECT_THAT(deck, HasSubstr("**   its moduli in 7 bins of 0.01 in ln E"));
}

TEST(CalculixDeck, EveryElementWithinItsBin)
{
  // Log-uniform moduli over a factor e^0.5 (a spread of 50 bin widths): at most 51 bins, every
  // written E within one bin width of the element's own, the Voigt bound kept exactly, the
  // Reuss bound within the bin width.
  std::mt19937 random(15);
  std::uniform_real_distribution<double> u(0, 0.5);
  mesh::TetMesh m = specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 6, 6, 6 },
    [&](const frep::Point3&) { return 500 * std::exp(u(random)); });
  for (const double w : { 0.01, 0.05 })
  {
    SCOPED_TRACE(w);
    const auto d = mesh::deckMaterials(m, w);
    const auto& e = mesh::findArray(m, "youngs_modulus")->values;
    double lowest = 1e300, highest = 0;
    for (double v : e)
    {
      lowest = std::min(lowest, v);
      highest = std::max(highest, v);
    }
    std::set<long long> occupied;
    for (double v : e)
    {
      occupied.insert(static_cast<long long>(std::floor(std::log(v / lowest) / w)));
    }
    EXPECT_EQ(d.size(), occupied.size());
    EXPECT_LE(d.size(), std::size_t(std::floor(std::log(highest / lowest) / w)) + 1);
    EXPECT_GE(d.size(), w == 0.01 ? 45u : 10u); // 1,296 samples fill nearly every bin
    const auto written = writtenModuli(m, d);
    double worst = 0, stiffness = 0, compliance = 0, volume = 0;
    for (std::size_t t = 0; t < e.size(); ++t)
    {
      ASSERT_FALSE(std::isnan(written[t])) << t;
      worst = std::max(worst, std::abs(std::log(written[t] / e[t])));
      const double v = volumeOf(m, t);
      volume += v;
      stiffness += v * e[t];
      compliance += v / e[t];
    }
    EXPECT_LT(worst, w);
    const auto bounds = mesh::voigtReuss(d);
    EXPECT_NEAR(bounds[0] / (stiffness / volume), 1, 1e-12);
    EXPECT_NEAR(bounds[1] / (volume / compliance), 1, w);
    std::printf(
      "bin width %.2f: %zu materials, worst |ln(E_written / E)| = %.5f\n", w, d.size(), worst);
  }
}

TEST(CalculixDeck, CellsWithinOneBinKeepOneMaterial)
{
  // Spread 0.9 % < 1 %: one material named after the cell, E its volume-weighted mean.
  mesh::TetMesh m = specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 2, 2, 2 },
    [](const frep::Point3& c) { return 1000 * (1 + 0.009 * c[0]); });
  const auto d = mesh::deckMaterials(m, 0.01);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].bin, 0);
  EXPECT_EQ(d[0].setName, "specimen");
  EXPECT_NEAR(d[0].youngsModulus, 1004.5, 1e-9); // the mean of a linear function
  EXPECT_NEAR(d[0].volume, 1, 1e-12);
  // The same mesh at infinite width; a wider spread at infinite width is one material too.
  EXPECT_EQ(mesh::deckMaterials(m, std::numeric_limits<double>::infinity()).size(), 1u);
  mesh::TetMesh wide = specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 2, 2, 2 },
    [](const frep::Point3& c) { return 1000 * (1 + c[0]); });
  EXPECT_GT(mesh::deckMaterials(wide, 0.01).size(), 1u);
  const auto one = mesh::deckMaterials(wide, std::numeric_limits<double>::infinity());
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0].youngsModulus, 1500, 1e-9);
  EXPECT_THROW(mesh::deckMaterials(m, 0), std::invalid_argument);
  EXPECT_THROW(mesh::deckMaterials(m, -0.01), std::invalid_argument);
}

TEST(CalculixDeck, ConstantCellsWriteTheDeckAsBefore)
{
  // A mesh whose cells have constant moduli: binning changes no byte of the deck.
  mesh::TetMesh m = specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 2, 2, 2 },
    [](const frep::Point3& c) { return c[2] < 0.5 ? 1000.0 : 3000.0; });
  m.materialNames = { "soft", "hard" };
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t)
  {
    m.materials[t] = centroid(m, t)[2] < 0.5 ? 1 : 2;
  }
  Scratch s("constant");
  mesh::AbaqusOptions binned, unbinned;
  unbinned.modulusBinWidth = std::numeric_limits<double>::infinity();
  mesh::writeAbaqus(m, s / "binned.inp", binned);
  mesh::writeAbaqus(m, s / "unbinned.inp", unbinned);
  const std::string deck = readText(s / "binned.inp");
  EXPECT_EQ(deck, readText(s / "unbinned.inp"));
  EXPECT_EQ(count(deck, "*MATERIAL"), 2u);
  EXPECT_EQ(count(deck, "*ELSET"), 0u);
}

// --- von Mises and the .frd reader -----------------------------------------------------------

TEST(CalculixFrd, VonMisesOfKnownTensors)
{
  EXPECT_NEAR(mesh::vonMises({ -10, 0, 0, 0, 0, 0 }), 10, 1e-12);               // uniaxial
  EXPECT_NEAR(mesh::vonMises({ 0, 0, 0, 5, 0, 0 }), 5 * std::sqrt(3.0), 1e-12); // pure shear
  EXPECT_NEAR(mesh::vonMises({ 0, 0, 0, 0, 0, 5 }), 5 * std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(mesh::vonMises({ -7, -7, -7, 0, 0, 0 }), 0, 1e-12); // hydrostatic
  EXPECT_NEAR(mesh::vonMises({ 1, 2, 3, 0, 0, 0 }), std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(mesh::vonMises({ 4, -4, 0, 0, 0, 0 }), 4 * std::sqrt(3.0), 1e-12); // plane shear
  // Invariant: the same state rotated by 45 deg about z is pure shear 4 in xy.
  EXPECT_NEAR(mesh::vonMises({ 0, 0, 0, 4, 0, 0 }), 4 * std::sqrt(3.0), 1e-12);
}

namespace
{
// Two tetrahedra, long format (node numbers of 10 columns), values touching, a DISP block with
// ccx's computed "ALL" component, a STRESS block, and a second increment's DISP that replaces the
// first.
const char* handFrd = R"(    1C
    1UUSER
    2C                             5                                     1
 -1         1 0.00000E+00 0.00000E+00 0.00000E+00
 -1         2 1.00000E+00 0.00000E+00 0.00000E+00
 -1         3 0.00000E+00 1.00000E+00 0.00000E+00
 -1         4 0.00000E+00 0.00000E+00 1.00000E+00
 -1         7 1.00000E+00 1.00000E+00 1.00000E+00
 -3
    3C                             2                                     1
 -1         1    3    0    1
 -2         1         2         3         4
 -1         2    3    0    1
 -2         2         3         4         7
 -3
    1PSTEP                         1           1           1
  100CL  101 0.500000000           5                     0    1           1
 -4  DISP        4    1
 -5  D1          1    2    1    0
 -5  D2          1    2    2    0
 -5  D3          1    2    3    0
 -5  ALL         1    2    0    0    1ALL
 -1         1 9.00000E+00 9.00000E+00 9.00000E+00
 -3
    1PSTEP                         2           1           1
  100CL  101 1.000000000           5                     0    1           1
 -4  DISP        4    1
 -5  D1          1    2    1    0
 -5  D2          1    2    2    0
 -5  D3          1    2    3    0
 -5  ALL         1    2    0    0    1ALL
 -1         1 0.00000E+00 0.00000E+00 0.00000E+00
 -1         2 3.00000E-03-1.50000E-03 0.00000E+00
 -1         3 0.00000E+00 3.00000E-03 0.00000E+00
 -1         4 0.00000E+00 0.00000E+00-1.00000E-02
 -1         7-1.25000E-04 2.50000E-04-1.00000E-02
 -3
    1PSTEP                         3           1           1
  100CL  101 1.000000000           5                     0    1           1
 -4  STRESS      6    1
 -5  SXX         1    4    1    1
 -5  SYY         1    4    2    2
 -5  SZZ         1    4    3    3
 -5  SXY         1    4    1    2
 -5  SYZ         1    4    2    3
 -5  SZX         1    4    3    1
 -1         1 1.00000E+00 2.00000E+00 3.00000E+00 0.00000E+00 0.00000E+00 0.00000E+00
 -1         2-1.00000E+01 0.00000E+00 0.00000E+00 0.00000E+00 0.00000E+00 0.00000E+00
 -1         3 0.00000E+00 0.00000E+00 0.00000E+00 5.00000E+00 0.00000E+00 0.00000E+00
 -1         4-7.00000E+00-7.00000E+00-7.00000E+00 0.00000E+00 0.00000E+00 0.00000E+00
 -1         7 0.00000E+00 0.00000E+00 0.00000E+00 0.00000E+00 0.00000E+00 5.00000E+00
 -3
 9999
)";

std::string writeText(const Scratch& s, const std::string& name, const std::string& text)
{
  std::ofstream(s / name, std::ios::binary) << text;
  return s / name;
}
} // namespace

TEST(CalculixFrd, ReadsAHandWrittenFile)
{
  Scratch s("frd");
  const mesh::FrdResults r = mesh::readFrd(writeText(s, "hand.frd", handFrd));
  ASSERT_EQ(r.nodes(), 5u);
  EXPECT_EQ(r.nodeIds, (std::vector<std::size_t>{ 1, 2, 3, 4, 7 }));
  EXPECT_EQ(r.index(7), 4u);
  EXPECT_THROW(r.index(5), std::out_of_range);
  EXPECT_EQ(r.points[4], (frep::Point3{ 1, 1, 1 }));
  ASSERT_EQ(r.elements.size(), 2u);
  EXPECT_EQ(r.elements[1].id, 2u);
  EXPECT_EQ(r.elements[1].type, 3);
  EXPECT_EQ(r.elements[1].nodes, (std::vector<std::size_t>{ 2, 3, 4, 7 }));
  ASSERT_EQ(r.displacement.size(), 5u);
  EXPECT_EQ(r.blocks.at("DISP").time, 1.0); // the last increment's
  EXPECT_EQ(r.blocks.at("DISP").components, (std::vector<std::string>{ "D1", "D2", "D3" }));
  EXPECT_EQ(r.displacement[0], (std::array<double, 3>{ 0, 0, 0 }));
  EXPECT_EQ(r.displacement[1], (std::array<double, 3>{ 3e-3, -1.5e-3, 0 }));
  EXPECT_EQ(r.displacement[4], (std::array<double, 3>{ -1.25e-4, 2.5e-4, -1e-2 }));
  ASSERT_EQ(r.stress.size(), 5u);
  EXPECT_EQ(r.stress[3], (std::array<double, 6>{ -7, -7, -7, 0, 0, 0 }));
  EXPECT_TRUE(r.force.empty());
  const double expected[5] = { std::sqrt(3.0), 10, 5 * std::sqrt(3.0), 0, 5 * std::sqrt(3.0) };
  for (std::size_t i = 0; i < 5; ++i)
  {
    EXPECT_NEAR(mesh::vonMises(r.stress[i]), expected[i], 1e-12) << i;
  }
}

TEST(CalculixFrd, ReadsTheShortFormat)
{
  // Format 0: node and element numbers of 5 columns.
  const std::string text =
    "    1C\n"
    "    2C                             2                                     0\n"
    " -1    1 1.00000E+00 2.00000E+00 3.00000E+00\n"
    " -1    2-1.00000E+00-2.00000E+00-3.00000E+00\n"
    " -3\n"
    "  100CL  101 1.000000000           2                     0    1           0\n"
    " -4  DISP        4    1\n"
    " -5  D1          1    2    1    0\n"
    " -5  D2          1    2    2    0\n"
    " -5  D3          1    2    3    0\n"
    " -5  ALL         1    2    0    0    1ALL\n"
    " -1    2 4.00000E+00 5.00000E+00 6.00000E+00\n"
    " -3\n"
    " 9999\n";
  Scratch s("frd0");
  const auto r = mesh::readFrd(writeText(s, "short.frd", text));
  ASSERT_EQ(r.nodes(), 2u);
  EXPECT_EQ(r.points[1], (frep::Point3{ -1, -2, -3 }));
  EXPECT_EQ(r.displacement[1], (std::array<double, 3>{ 4, 5, 6 }));
  EXPECT_TRUE(std::isnan(r.displacement[0][0])); // node 1 left out of the block
}

TEST(CalculixFrd, ReadsContinuationRecords)
{
  // More than six components: a node's values go on over ' -2' records whose number columns
  // are blank (5 in format 0).
  std::string text = "    2C                             1                                     0\n"
                     " -1    1 0.00000E+00 0.00000E+00 0.00000E+00\n"
                     " -3\n"
                     "  100CL  101 2.000000000           1                     0    1           0\n"
                     " -4  MANY        8    1\n";
  for (int c = 1; c <= 8; ++c)
  {
    text += " -5  C" + std::to_string(c) + "          1    1    0    0\n";
  }
  text += " -1    1 1.00000E+00 2.00000E+00 3.00000E+00 4.00000E+00 5.00000E+00 6.00000E+00\n"
          " -2      7.00000E+00-8.00000E+00\n"
          " -3\n"
          " 9999\n";
  Scratch s("frd8");
  const auto r = mesh::readFrd(writeText(s, "many.frd", text));
  const mesh::FrdBlock& b = r.blocks.at("MANY");
  EXPECT_EQ(b.time, 2.0);
  ASSERT_EQ(b.components.size(), 8u);
  EXPECT_EQ(b.values, (std::vector<double>{ 1, 2, 3, 4, 5, 6, 7, -8 }));
}

TEST(CalculixFrd, ErrorsNameFileAndLine)
{
  Scratch s("frdbad");
  auto message = [&](const std::string& text)
  {
    const std::string path = writeText(s, "bad.frd", text);
    try
    {
      mesh::readFrd(path);
    }
    catch (const std::runtime_error& e)
    {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string full = handFrd;
  // A number cut: "3.00000E-0x".
  std::string bad = full;
  bad.replace(bad.find("3.00000E-03-1.5"), 11, "3.00000E-0x");
  EXPECT_THAT(message(bad), HasSubstr("bad.frd:33: expected a value"));
  // Truncated: no "9999".
  EXPECT_THAT(message(full.substr(0, full.find(" 9999"))), HasSubstr("truncated"));
  // Cut inside a block.
  EXPECT_THAT(message(full.substr(0, full.find(" -1         3 0.00000E+00 3.0"))),
    HasSubstr("result block DISP has no end"));
  // A result for a node that is not there.
  bad = full;
  bad.replace(bad.find(" -1         7-1.25"), 13, " -1         8");
  EXPECT_THAT(message(bad), HasSubstr("bad.frd:36: node 8 is not in the node block"));
  EXPECT_THAT(message(""), HasSubstr("has no nodes"));
  EXPECT_THROW(mesh::readFrd(s / "missing.frd"), std::runtime_error);
}

// --- running ccx ------------------------------------------------------------------------------

TEST(CalculixRun, MissingSolverAndFailingDeckAreClearErrors)
{
  Scratch s("run");
  mesh::TetMesh m =
    specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 1, 1, 1 }, [](const frep::Point3&) { return 1000.0; });
  mesh::AbaqusOptions broken;
  broken.appendix = "*STEP\n*STATIC\n*BOUNDARY\nNO_SUCH_SET, 1, 3\n*END STEP\n";
  mesh::writeAbaqus(m, s / "broken.inp", broken);
  mesh::CalculixOptions missing;
  missing.executable = "ictk-no-such-ccx";
  try
  {
    mesh::runCalculix(s / "broken.inp", missing);
    FAIL() << "no error";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("broken.inp"));
    EXPECT_THAT(e.what(), HasSubstr("'ictk-no-such-ccx' was not found"));
    EXPECT_THAT(e.what(), HasSubstr("calculix-ccx"));
  }
  try
  {
    mesh::runCalculix(s / "broken.inp", ccx());
    FAIL() << "no error";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("CalculiX failed on '" + (s / "broken.inp") + "'"));
    EXPECT_THAT(e.what(), HasSubstr("broken.log"));
    EXPECT_THAT(e.what(), HasSubstr("  | ")); // the log's last lines
  }
  EXPECT_TRUE(fs::exists(s / "broken.log"));
}

TEST(CalculixRun, Cancels)
{
  Scratch s("cancel");
  mesh::TetMesh m =
    specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 2, 2, 2 }, [](const frep::Point3&) { return 1000.0; });
  mesh::CompressionOptions o;
  o.displacement = 0.01;
  mesh::writeCompressionDeck(m, s / "job.inp", o);
  auto options = ccx();
  options.progress = [](double)
  {
    return false;
  };
  EXPECT_THROW(mesh::runCalculix(s / "job.inp", options), Cancelled);
}

// --- compression ------------------------------------------------------------------------------

namespace
{
/// An element's E as a written .inp gives it, read independently of the writer: *ELEMENT and
/// *ELSET sets, *MATERIAL / *ELASTIC, *SOLID SECTION (element id -> E; an element given two
/// sections is NaN).
std::map<std::size_t, double> deckModuli(const std::string& path)
{
  std::map<std::string, std::vector<std::size_t>> sets;
  std::map<std::string, double> modulus;
  std::vector<std::pair<std::string, std::string>> sections; // (elset, material)
  std::ifstream in(path);
  std::string line, keyword, set, material;
  auto parameter = [](const std::string& l, const std::string& name)
  {
    const auto at = l.find(name + "=");
    return at == std::string::npos
      ? std::string()
      : l.substr(at + name.size() + 1, l.find(',', at) - at - name.size() - 1);
  };
  while (std::getline(in, line))
  {
    if (line.rfind("**", 0) == 0)
    {
      continue;
    }
    if (line[0] == '*')
    {
      keyword = line.substr(0, line.find(','));
      set = parameter(line, "ELSET");
      if (keyword == "*MATERIAL")
      {
        material = parameter(line, "NAME");
      }
      if (keyword == "*SOLID SECTION")
      {
        sections.emplace_back(set, parameter(line, "MATERIAL"));
      }
      continue;
    }
    std::istringstream fields(line);
    std::string field;
    if (keyword == "*ELASTIC")
    {
      std::getline(fields, field, ',');
      modulus[material] = std::stod(field);
    }
    else if (keyword == "*ELEMENT")
    {
      std::getline(fields, field, ',');
      sets[set].push_back(std::stoul(field));
    }
    else if (keyword == "*ELSET")
    {
      while (std::getline(fields, field, ','))
      {
        sets[set].push_back(std::stoul(field));
      }
    }
  }
  std::map<std::size_t, double> e;
  for (const auto& [elset, name] : sections)
  {
    for (const std::size_t id : sets.at(elset))
    {
      e[id] = e.count(id) ? std::nan("") : modulus.at(name);
    }
  }
  return e;
}

mesh::CompressionResult compress(const mesh::TetMesh& m, const Scratch& s, double d)
{
  mesh::CompressionOptions o;
  o.displacement = d;
  return mesh::solveCompression(m, s.dir.string(), o, ccx());
}
} // namespace

TEST(CalculixCompression, HomogeneousBoxIsVoigt)
{
  // [0, 2] x [0, 1] x [0, 3], E = 1000, nu = 0.3, d = 0.003: uniaxial stress sigma_zz = -E d / H
  // = -1 everywhere, lateral expansion nu d / H about the anchor, F = E A d / H = 2.
  const double e = 1000, d = 0.003, h = 3;
  const mesh::TetMesh m =
    specimen({ { 0, 0, 0 }, { 2, 1, 3 } }, { 4, 2, 6 }, [&](const frep::Point3&) { return e; });
  Scratch s("homogeneous");
  const auto r = compress(m, s, d);
  const auto& c = r.compression;
  EXPECT_NEAR(c.voigtModulus, e, 1e-9);
  EXPECT_NEAR(c.reussModulus, e, 1e-9);
  EXPECT_NEAR(c.area, 2, 1e-12);
  EXPECT_EQ(c.bottomNodes.size(), 15u);
  EXPECT_EQ(c.topNodes.size(), 15u);
  EXPECT_NEAR(r.apparentModulus / c.voigtModulus, 1, 0.005);
  EXPECT_NEAR(-r.topForce[2], 2, 2e-5);
  EXPECT_NEAR(r.bottomForce[2], -r.topForce[2], 1e-5); // equilibrium
  for (int a = 0; a < 2; ++a)
  {
    EXPECT_NEAR(r.topForce[std::size_t(a)], 0, 1e-6);
    EXPECT_NEAR(r.bottomForce[std::size_t(a)], 0, 1e-6);
  }
  // The .frd: the top at -d, the bottom at 0, the sides expanding freely, uniaxial stress.
  const mesh::FrdResults frd = mesh::readFrd(r.run.frd);
  const mesh::PointResults p = mesh::resultsOnMesh(m, frd);
  ASSERT_EQ(p.displacement.size(), m.points.size());
  ASSERT_EQ(frd.elements.size(), m.tetrahedra.size());
  for (const mesh::FrdElement& element : frd.elements)
  {
    ASSERT_EQ(element.type, 3);
    const auto& k = m.tetrahedra[element.id - 1];
    EXPECT_EQ(element.nodes, (std::vector<std::size_t>{ k[0] + 1, k[1] + 1, k[2] + 1, k[3] + 1 }));
  }
  const auto& anchor = m.points[c.anchorNode - 1];
  double worstU = 0, worstS = 0;
  for (std::size_t i = 0; i < m.points.size(); ++i)
  {
    const auto& x = m.points[i];
    const std::array<double, 3> exact = { 0.3 * d / h * (x[0] - anchor[0]),
      0.3 * d / h * (x[1] - anchor[1]), -d * x[2] / h };
    for (int a = 0; a < 3; ++a)
    {
      worstU =
        std::max(worstU, std::abs(p.displacement[i][std::size_t(a)] - exact[std::size_t(a)]));
    }
    worstS = std::max(worstS, std::abs(p.vonMises[i] - e * d / h));
    EXPECT_NEAR(p.stress[i][2], -e * d / h, 1e-4);
  }
  for (auto id : c.topNodes)
  {
    EXPECT_EQ(frd.displacement[frd.index(id)][2], -d);
  }
  EXPECT_LT(worstU, 1e-8); // 5 significant digits of 1e-3
  EXPECT_LT(worstS, 1e-4);
  ASSERT_EQ(frd.force.size(), m.points.size());
  double top = 0;
  for (auto id : c.topNodes)
  {
    top += frd.force[frd.index(id)][2];
  }
  EXPECT_NEAR(top, r.topForce[2], 1e-4);
  std::printf("homogeneous box: %zu tetrahedra, E_app / Voigt = %.7f, ccx %.3f s\n",
    m.tetrahedra.size(), r.apparentModulus / c.voigtModulus, r.run.seconds);
}

TEST(CalculixCompression, LayersInSeriesAreReussInParallelVoigt)
{
  // Two halves of E 1000 and 3000: stacked along z the iso-stress (Reuss) modulus
  // 1 / (0.5 / 1000 + 0.5 / 3000) = 1500, side by side along x the iso-strain (Voigt) 2000.
  // Side by side both halves shorten and expand alike, so the uniform strain is exact for any
  // nu. Stacked, the halves expand differently (nu sigma / E) and the interface holds them
  // together: exact with nu = 0, stiffer than Reuss by an amount that fades with the layers'
  // height / width (1.1 % at 1 : 1, measured; 0.5 % at 2 : 1 with nu = 0.3).
  const double soft = 1000, hard = 3000;
  const frep::Box3 box{ { 0, 0, 0 }, { 1, 1, 4 } };
  auto stacked = [&](const frep::Point3& c)
  {
    return c[2] < 2 ? soft : hard;
  };
  auto sideBySide = [&](const frep::Point3& c)
  {
    return c[0] < 0.5 ? soft : hard;
  };
  for (const double nu : { 0.0, 0.3 })
  {
    SCOPED_TRACE(nu);
    const mesh::TetMesh series = specimen(box, { 4, 4, 16 }, stacked, nu);
    const mesh::TetMesh parallel = specimen(box, { 4, 4, 16 }, sideBySide, nu);
    Scratch s1("series"), s2("parallel");
    const auto r1 = compress(series, s1, 0.004);
    const auto r2 = compress(parallel, s2, 0.004);
    EXPECT_EQ(r1.compression.materials.size(), 2u); // one cell, two bins
    for (const auto* r : { &r1, &r2 })
    {
      EXPECT_NEAR(r->compression.reussModulus, 1500, 1e-9);
      EXPECT_NEAR(r->compression.voigtModulus, 2000, 1e-9);
    }
    EXPECT_NEAR(r1.apparentModulus / 1500, 1, nu == 0 ? 1e-5 : 0.01);
    EXPECT_NEAR(r2.apparentModulus / 2000, 1, 1e-5);
    EXPECT_GE(r1.apparentModulus, 1500 * (1 - 1e-5));
    EXPECT_LE(r2.apparentModulus, 2000 * (1 + 1e-5));
    std::printf("nu = %.1f, %zu tetrahedra: series E_app / Reuss = %.6f (ccx %.3f s); parallel "
                "E_app / Voigt = %.6f (ccx %.3f s)\n",
      nu, series.tetrahedra.size(), r1.apparentModulus / 1500, r1.run.seconds,
      r2.apparentModulus / 2000, r2.run.seconds);
  }
}

TEST(CalculixCompression, RandomModulusLiesBetweenTheBounds)
{
  // E per tetrahedron log-uniform in [100, 10000] from a fixed seed, binned at 1 %.
  std::mt19937 random(2026);
  std::uniform_real_distribution<double> u(std::log(100.0), std::log(10000.0));
  const mesh::TetMesh m = specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 6, 6, 6 },
    [&](const frep::Point3&) { return std::exp(u(random)); });
  Scratch s("random");
  const auto r = compress(m, s, 0.001);
  const auto& c = r.compression;
  EXPECT_GT(c.materials.size(), 300u);
  EXPECT_LE(c.reussModulus, r.apparentModulus);
  EXPECT_LE(r.apparentModulus, c.voigtModulus);
  // The bounds are those of the deck as written: every element in one solid section, its E
  // within one bin width of its own.
  const auto written = deckModuli(s / "compression.inp");
  ASSERT_EQ(written.size(), m.tetrahedra.size());
  const auto& e = mesh::findArray(m, "youngs_modulus")->values;
  double volume = 0, stiffness = 0, compliance = 0, worst = 0;
  for (const auto& [id, modulus] : written)
  {
    ASSERT_FALSE(std::isnan(modulus)) << "element " << id << " has two sections";
    const double v = volumeOf(m, id - 1);
    volume += v;
    stiffness += v * modulus;
    compliance += v / modulus;
    worst = std::max(worst, std::abs(std::log(modulus / e[id - 1])));
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_NEAR(c.voigtModulus / (stiffness / volume), 1, 1e-11);
  EXPECT_NEAR(c.reussModulus / (volume / compliance), 1, 1e-11);
  std::printf("random box: %zu tetrahedra, %zu materials, Reuss %.2f <= E_app %.2f <= Voigt "
              "%.2f (E_app / Voigt %.4f, / Reuss %.4f), ccx %.3f s\n",
    m.tetrahedra.size(), c.materials.size(), c.reussModulus, r.apparentModulus, c.voigtModulus,
    r.apparentModulus / c.voigtModulus, r.apparentModulus / c.reussModulus, r.run.seconds);
}

TEST(CalculixCompression, RefusesWhatIsNoCompressionCase)
{
  const mesh::TetMesh m =
    specimen({ { 0, 0, 0 }, { 1, 1, 1 } }, { 1, 1, 1 }, [](const frep::Point3&) { return 1000.0; });
  mesh::CompressionOptions o;
  EXPECT_THROW(mesh::compressionCase(m, o, nullptr), std::invalid_argument); // d = 0
  o.displacement = std::nan("");
  EXPECT_THROW(mesh::compressionCase(m, o, nullptr), std::invalid_argument);
  o.displacement = 0.01;
  const auto c = mesh::compressionCase(m, o, nullptr);
  EXPECT_EQ(c.bottomNodes.size(), 4u);
  EXPECT_NE(c.anchorNode, c.rollerNode);
  // No modulus: the cell is named, and the folder solveCompression would have made is not left.
  mesh::TetMesh bare = m;
  bare.cellData.clear();
  Scratch s("refused");
  try
  {
    mesh::solveCompression(bare, s / "work", o, ccx());
    FAIL() << "no error";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(),
      HasSubstr("cell 'specimen') is a solver-unfriendly material: no "
                "youngs_modulus attribute"));
  }
  EXPECT_FALSE(fs::exists(s / "work"));
}
