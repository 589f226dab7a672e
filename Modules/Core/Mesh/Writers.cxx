// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/Writers.h"

#include "Mesh/Quality.h"
#include "Mesh/TetAttributes.h"
#include "Mesh/Validity.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <stdexcept>

namespace ictk::mesh
{

namespace
{

namespace fs = std::filesystem;

/// printf into a FILE*, remembering the first failure.
class Out
{
public:
  explicit Out(std::FILE* f)
    : f_(f)
  {
  }
  template <typename... Args>
  void print(const char* format, Args... args)
  {
    if (std::fprintf(f_, format, args...) < 0)
    {
      failed_ = true;
    }
  }
  void text(const std::string& s)
  {
    if (std::fwrite(s.data(), 1, s.size(), f_) != s.size())
    {
      failed_ = true;
    }
  }
  bool failed() const { return failed_; }

private:
  std::FILE* f_;
  bool failed_ = false;
};

/// Writes `path` through a temporary file in the same folder, renamed into place on success.
void writeAtomically(const std::string& path, const std::function<void(Out&)>& body)
{
  std::error_code ec;
  if (fs::is_directory(path, ec))
  {
    throw std::runtime_error("cannot write '" + path + "': it is a directory");
  }
  std::random_device random;
  const std::string temporary = path + ".tmp-" + std::to_string(random() % 1000000000u);
  std::FILE* f = std::fopen(temporary.c_str(), "wb");
  if (!f)
  {
    throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
  }
  auto discard = [&]()
  {
    std::remove(temporary.c_str());
  };
  bool closed = false;
  try
  {
    Out out(f);
    body(out);
    const bool ok = !out.failed() && std::fflush(f) == 0 && !std::ferror(f);
    const int error = errno;
    closed = true;
    if (std::fclose(f) != 0 || !ok)
    {
      throw std::runtime_error("cannot write '" + path + "': " + std::strerror(error));
    }
  }
  catch (...)
  {
    if (!closed)
    {
      std::fclose(f);
    }
    discard();
    throw;
  }
  fs::rename(temporary, path, ec);
  if (ec)
  {
    discard();
    throw std::runtime_error("cannot write '" + path + "': " + ec.message());
  }
}

void checkWritable(const TetMesh& mesh, const std::string& path)
{
  if (mesh.tetrahedra.empty())
  {
    throw std::invalid_argument("cannot write '" + path + "': the mesh has no tetrahedra");
  }
  // Everything but the boundary check, which needs the complex (the backends run that).
  try
  {
    requireValid(checkValidity(mesh, mesh.size), "the mesh");
  }
  catch (const std::invalid_argument& e)
  {
    throw std::invalid_argument("cannot write '" + path + "': " + e.what());
  }
}

/// Tetrahedra per material (index = material id - 1).
std::vector<std::vector<std::size_t>> byMaterial(const TetMesh& mesh)
{
  std::vector<std::vector<std::size_t>> groups(mesh.materialNames.size());
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    groups[static_cast<std::size_t>(mesh.materials[t] - 1)].push_back(t);
  }
  return groups;
}

std::string quoted(const std::string& name)
{
  std::string s = name;
  std::replace(s.begin(), s.end(), '"', '\'');
  std::replace(s.begin(), s.end(), '\n', ' ');
  return "\"" + s + "\"";
}

void writeGmsh22(const TetMesh& mesh, Out& out)
{
  const auto groups = byMaterial(mesh);
  out.print("$MeshFormat\n2.2 0 %d\n$EndMeshFormat\n", static_cast<int>(sizeof(double)));
  std::size_t used = 0;
  for (const auto& g : groups)
  {
    used += g.empty() ? 0 : 1;
  }
  out.print("$PhysicalNames\n%zu\n", used);
  for (std::size_t m = 0; m < groups.size(); ++m)
  {
    if (!groups[m].empty())
    {
      out.print("3 %zu %s\n", m + 1, quoted(mesh.materialNames[m]).c_str());
    }
  }
  out.print("$EndPhysicalNames\n$Nodes\n%zu\n", mesh.points.size());
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
  {
    const auto& p = mesh.points[i];
    out.print("%zu %.17g %.17g %.17g\n", i + 1, p[0], p[1], p[2]);
  }
  out.print("$EndNodes\n$Elements\n%zu\n", mesh.tetrahedra.size());
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    const auto& k = mesh.tetrahedra[t];
    const int m = mesh.materials[t];
    out.print("%zu 4 2 %d %d %u %u %u %u\n", t + 1, m, m, k[0] + 1, k[1] + 1, k[2] + 1, k[3] + 1);
  }
  out.print("$EndElements\n");
}

void writeGmsh41(const TetMesh& mesh, Out& out)
{
  const auto groups = byMaterial(mesh);
  std::vector<std::size_t> used;
  for (std::size_t m = 0; m < groups.size(); ++m)
  {
    if (!groups[m].empty())
    {
      used.push_back(m);
    }
  }
  // Each point belongs to the node block of the first material (volume entity) that uses it.
  constexpr auto none = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> owner(mesh.points.size(), none);
  std::vector<std::array<double, 6>> box(groups.size());
  for (auto m : used)
  {
    const double inf = std::numeric_limits<double>::infinity();
    box[m] = { inf, inf, inf, -inf, -inf, -inf };
    for (auto t : groups[m])
    {
      for (auto i : mesh.tetrahedra[t])
      {
        owner[i] = std::min(owner[i], m);
        for (int a = 0; a < 3; ++a)
        {
          box[m][a] = std::min(box[m][a], mesh.points[i][a]);
          box[m][3 + a] = std::max(box[m][3 + a], mesh.points[i][a]);
        }
      }
    }
  }
  std::vector<std::vector<std::size_t>> nodes(groups.size());
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
  {
    // Points no tetrahedron uses go with the first volume.
    nodes[owner[i] == none ? used.front() : owner[i]].push_back(i);
  }

  out.print("$MeshFormat\n4.1 0 %d\n$EndMeshFormat\n", static_cast<int>(sizeof(double)));
  out.print("$PhysicalNames\n%zu\n", used.size());
  for (auto m : used)
  {
    out.print("3 %zu %s\n", m + 1, quoted(mesh.materialNames[m]).c_str());
  }
  out.print("$EndPhysicalNames\n$Entities\n0 0 0 %zu\n", used.size());
  for (auto m : used)
  {
    const auto& b = box[m];
    out.print("%zu %.17g %.17g %.17g %.17g %.17g %.17g 1 %zu 0\n", m + 1, b[0], b[1], b[2], b[3],
      b[4], b[5], m + 1);
  }
  out.print(
    "$EndEntities\n$Nodes\n%zu %zu 1 %zu\n", used.size(), mesh.points.size(), mesh.points.size());
  for (auto m : used)
  {
    out.print("3 %zu 0 %zu\n", m + 1, nodes[m].size());
    for (auto i : nodes[m])
    {
      out.print("%zu\n", i + 1);
    }
    for (auto i : nodes[m])
    {
      const auto& p = mesh.points[i];
      out.print("%.17g %.17g %.17g\n", p[0], p[1], p[2]);
    }
  }
  out.print("$EndNodes\n$Elements\n%zu %zu 1 %zu\n", used.size(), mesh.tetrahedra.size(),
    mesh.tetrahedra.size());
  for (auto m : used)
  {
    out.print("3 %zu 4 %zu\n", m + 1, groups[m].size());
    for (auto t : groups[m])
    {
      const auto& k = mesh.tetrahedra[t];
      out.print("%zu %u %u %u %u\n", t + 1, k[0] + 1, k[1] + 1, k[2] + 1, k[3] + 1);
    }
  }
  out.print("$EndElements\n");
}

std::string upper(std::string s)
{
  for (auto& c : s)
  {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return s;
}

} // namespace

void writeGmsh(const TetMesh& mesh, const std::string& path, GmshVersion version)
{
  checkWritable(mesh, path);
  writeAtomically(path,
    [&](Out& out)
    {
      if (version == GmshVersion::V22)
      {
        writeGmsh22(mesh, out);
      }
      else
      {
        writeGmsh41(mesh, out);
      }
    });
}

void writeMedit(const TetMesh& mesh, const std::string& path)
{
  checkWritable(mesh, path);
  writeAtomically(path,
    [&](Out& out)
    {
      out.print("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n%zu\n", mesh.points.size());
      for (const auto& p : mesh.points)
      {
        out.print("%.17g %.17g %.17g 0\n", p[0], p[1], p[2]);
      }
      out.print("\nTetrahedra\n%zu\n", mesh.tetrahedra.size());
      for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
      {
        const auto& k = mesh.tetrahedra[t];
        out.print("%u %u %u %u %d\n", k[0] + 1, k[1] + 1, k[2] + 1, k[3] + 1,
          static_cast<int>(mesh.materials[t]));
      }
      out.print("\nEnd\n");
    });
}

std::vector<std::string> abaqusSetNames(const TetMesh& mesh)
{
  std::vector<std::string> names;
  std::set<std::string> taken;
  for (std::size_t m = 0; m < mesh.materialNames.size(); ++m)
  {
    std::string s;
    for (char c : mesh.materialNames[m])
    {
      const bool word = std::isalnum(static_cast<unsigned char>(c)) || c == '_';
      s += word && static_cast<unsigned char>(c) < 128 ? c : '_';
    }
    if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0])))
    {
      s = "M" + s;
    }
    s = s.substr(0, 72);
    std::string candidate = s;
    for (int k = 2; taken.count(upper(candidate)); ++k)
    {
      candidate = s + "_" + std::to_string(k);
    }
    taken.insert(upper(candidate));
    names.push_back(candidate);
  }
  return names;
}

std::vector<SolidMaterial> solidMaterials(const TetMesh& mesh)
{
  validate(mesh);
  const auto groups = byMaterial(mesh);
  const auto setNames = abaqusSetNames(mesh);
  const TetArray* e = findArray(mesh, "youngs_modulus");
  const TetArray* nu = findArray(mesh, "poisson_ratio");
  const TetArray* rho = findArray(mesh, "density");
  std::vector<SolidMaterial> out;
  for (std::size_t m = 0; m < groups.size(); ++m)
  {
    if (groups[m].empty())
    {
      continue;
    }
    const std::string& name = mesh.materialNames[m];
    auto unfriendly = [&](const std::string& why)
    {
      return std::invalid_argument("material " + std::to_string(m + 1) + " (cell '" + name +
        "') is a solver-unfriendly material: " + why);
    };
    // Volume-weighted mean of a scalar array over the material's tetrahedra.
    auto mean = [&](const TetArray& a, const char* what, auto accept)
    {
      if (a.components != 1)
      {
        throw unfriendly(
          std::string(what) + " has " + std::to_string(a.components) + " components, not 1");
      }
      double sum = 0, volume = 0;
      for (auto t : groups[m])
      {
        const double v = a.values[t];
        if (!accept(v))
        {
          throw unfriendly(std::string(what) + " is " + std::to_string(v) + " on tetrahedron " +
            std::to_string(t));
        }
        const auto& k = mesh.tetrahedra[t];
        const double w =
          tetShape(mesh.points[k[0]], mesh.points[k[1]], mesh.points[k[2]], mesh.points[k[3]])
            .volume;
        sum += w * v;
        volume += w;
      }
      return sum / volume;
    };
    if (!e)
    {
      throw unfriendly("no youngs_modulus attribute");
    }
    SolidMaterial s;
    s.material = static_cast<std::int32_t>(m + 1);
    s.name = name;
    s.setName = setNames[m];
    s.tetrahedra = groups[m].size();
    s.youngsModulus =
      mean(*e, "youngs_modulus", [](double v) { return std::isfinite(v) && v > 0; });
    s.poissonRatio = nu
      ? mean(*nu, "poisson_ratio", [](double v) { return std::isfinite(v) && v > -1 && v < 0.5; })
      : 0.0;
    s.density = rho ? mean(*rho, "density", [](double v) { return std::isfinite(v) && v > 0; })
                    : std::numeric_limits<double>::quiet_NaN();
    out.push_back(s);
  }
  return out;
}

std::vector<DeckMaterial> deckMaterials(const TetMesh& mesh, double binWidth)
{
  if (!(binWidth > 0))
  {
    throw std::invalid_argument(
      "the modulus bin width must be positive (in ln E), not " + std::to_string(binWidth));
  }
  const std::vector<SolidMaterial> cells = solidMaterials(mesh);
  const auto groups = byMaterial(mesh);
  const TetArray* e = findArray(mesh, "youngs_modulus");
  const TetArray* nu = findArray(mesh, "poisson_ratio");
  const TetArray* rho = findArray(mesh, "density");
  auto volume = [&](std::size_t t)
  {
    const auto& k = mesh.tetrahedra[t];
    return tetShape(mesh.points[k[0]], mesh.points[k[1]], mesh.points[k[2]], mesh.points[k[3]])
      .volume;
  };
  std::set<std::string> taken;
  for (const auto& name : abaqusSetNames(mesh))
  {
    taken.insert(upper(name));
  }
  std::vector<DeckMaterial> out;
  for (const SolidMaterial& cell : cells)
  {
    const auto& tets = groups[static_cast<std::size_t>(cell.material - 1)];
    double lowest = std::numeric_limits<double>::infinity(), highest = 0;
    for (auto t : tets)
    {
      lowest = std::min(lowest, e->values[t]);
      highest = std::max(highest, e->values[t]);
    }
    // The bin of each tetrahedron, counted from the cell's smallest modulus; one bin: the cell.
    std::map<long long, std::vector<std::size_t>> bins;
    if (std::log(highest / lowest) >= binWidth)
    {
      for (auto t : tets)
      {
        bins[static_cast<long long>(std::floor(std::log(e->values[t] / lowest) / binWidth))]
          .push_back(t);
      }
    }
    if (bins.size() <= 1)
    {
      DeckMaterial d;
      d.material = cell.material;
      d.setName = cell.setName;
      d.tetrahedra = tets;
      for (auto t : tets)
      {
        d.volume += volume(t);
      }
      d.youngsModulus = cell.youngsModulus;
      d.poissonRatio = cell.poissonRatio;
      d.density = cell.density;
      out.push_back(std::move(d));
      continue;
    }
    for (auto& [k, members] : bins)
    {
      DeckMaterial d;
      d.material = cell.material;
      d.bin = static_cast<int>(k + 1);
      const std::string suffix = "_E" + std::to_string(d.bin);
      const std::string base = cell.setName.substr(0, 76 - suffix.size()) + suffix;
      d.setName = base;
      for (int n = 2; taken.count(upper(d.setName)); ++n)
      {
        d.setName = base + "_" + std::to_string(n);
      }
      taken.insert(upper(d.setName));
      double sumE = 0, sumNu = 0, sumRho = 0;
      for (auto t : members)
      {
        const double v = volume(t);
        d.volume += v;
        sumE += v * e->values[t];
        sumNu += nu ? v * nu->values[t] : 0.0;
        sumRho += rho ? v * rho->values[t] : 0.0;
      }
      d.youngsModulus = sumE / d.volume;
      d.poissonRatio = sumNu / d.volume;
      d.density = rho ? sumRho / d.volume : std::numeric_limits<double>::quiet_NaN();
      d.tetrahedra = std::move(members);
      out.push_back(std::move(d));
    }
  }
  return out;
}

void writeAbaqus(const TetMesh& mesh, const std::string& path, const AbaqusOptions& options)
{
  checkWritable(mesh, path);
  std::vector<DeckMaterial> materials;
  if (options.materials)
  {
    try
    {
      materials = deckMaterials(mesh, options.modulusBinWidth);
    }
    catch (const std::invalid_argument& e)
    {
      throw std::invalid_argument("cannot write '" + path + "': " + e.what());
    }
  }
  const auto groups = byMaterial(mesh);
  const auto setNames = abaqusSetNames(mesh);
  writeAtomically(path,
    [&](Out& out)
    {
      out.print("*HEADING\n");
      if (options.heading.empty())
      {
        out.print("ICTK tetrahedral mesh: %zu nodes, %zu C3D4 elements\n", mesh.points.size(),
          mesh.tetrahedra.size());
      }
      else
      {
        std::string h = options.heading;
        std::replace(h.begin(), h.end(), '\n', ' ');
        out.print("%s\n", h.c_str());
      }
      for (std::size_t m = 0; m < groups.size(); ++m)
      {
        if (!groups[m].empty())
        {
          std::string n = mesh.materialNames[m];
          std::replace(n.begin(), n.end(), '\n', ' ');
          out.print(
            "** material %zu: ELSET %s = cell '%s'\n", m + 1, setNames[m].c_str(), n.c_str());
          const auto bins = std::count_if(materials.begin(), materials.end(),
            [&](const DeckMaterial& d) { return d.material == std::int32_t(m + 1) && d.bin > 0; });
          if (bins > 0)
          {
            out.print("**   its moduli in %zu bins of %.6g in ln E: ELSETs %s_E<bin>\n",
              static_cast<std::size_t>(bins), options.modulusBinWidth, setNames[m].c_str());
          }
        }
      }
      out.print("*NODE, NSET=NALL\n");
      for (std::size_t i = 0; i < mesh.points.size(); ++i)
      {
        const auto& p = mesh.points[i];
        out.print("%zu, %.12e, %.12e, %.12e\n", i + 1, p[0], p[1], p[2]);
      }
      for (std::size_t m = 0; m < groups.size(); ++m)
      {
        if (groups[m].empty())
        {
          continue;
        }
        out.print("*ELEMENT, TYPE=C3D4, ELSET=%s\n", setNames[m].c_str());
        for (auto t : groups[m])
        {
          const auto& k = mesh.tetrahedra[t];
          out.print("%zu, %u, %u, %u, %u\n", t + 1, k[0] + 1, k[1] + 1, k[2] + 1, k[3] + 1);
        }
      }
      for (const auto& s : materials)
      {
        if (s.bin > 0)
        {
          out.print("*ELSET, ELSET=%s\n", s.setName.c_str());
          for (std::size_t i = 0; i < s.tetrahedra.size(); ++i)
          {
            const bool last = i + 1 == s.tetrahedra.size() || (i + 1) % 16 == 0;
            out.print(last ? "%zu\n" : "%zu, ", s.tetrahedra[i] + 1);
          }
        }
        out.print("*MATERIAL, NAME=%s\n*ELASTIC\n%.12e, %.12e\n", s.setName.c_str(),
          s.youngsModulus, s.poissonRatio);
        if (std::isfinite(s.density))
        {
          out.print("*DENSITY\n%.12e\n", s.density);
        }
        out.print("*SOLID SECTION, ELSET=%s, MATERIAL=%s\n", s.setName.c_str(), s.setName.c_str());
      }
      if (!options.appendix.empty())
      {
        out.text(options.appendix);
        if (options.appendix.back() != '\n')
        {
          out.text("\n");
        }
      }
    });
}

void writeTetMesh(const TetMesh& mesh, const std::string& path)
{
  std::string ext = fs::path(path).extension().string();
  for (auto& c : ext)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (ext == ".msh")
  {
    writeGmsh(mesh, path, GmshVersion::V41);
  }
  else if (ext == ".inp")
  {
    writeAbaqus(mesh, path);
  }
  else if (ext == ".mesh")
  {
    writeMedit(mesh, path);
  }
  else
  {
    throw std::invalid_argument("'" + path + "' is not a .msh, .inp or .mesh file");
  }
}

} // namespace ictk::mesh
