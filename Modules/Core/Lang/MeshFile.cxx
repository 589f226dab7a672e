// SPDX-License-Identifier: BSD-3-Clause
// .obj, .off, .ply and .stl triangle meshes (MeshFile.h): readers of vertices and faces.
#include "Lang/MeshFile.h"

#include "Lang/Diagnostics.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

namespace ictk::lang
{
namespace
{

bool endsWith(std::string s, const char* ext)
{
  std::transform(s.begin(), s.end(), s.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string e(ext);
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

/// The reader's state: the file, the line being read, and what it has made so far.
struct Reader
{
  std::string path;
  int line = 0;
  std::string text;
  complex::ExplicitGeometry mesh;

  [[noreturn]] void fail(const std::string& message) const
  {
    Diagnostic d;
    d.where.file = path;
    d.where.line = line;
    d.message = message;
    d.sourceLine = text;
    throw ParseError({ d });
  }

  double number(std::istringstream& in, const char* what)
  {
    std::string word;
    if (!(in >> word))
      fail(std::string("missing ") + what);
    char* end = nullptr;
    const double v = std::strtod(word.c_str(), &end);
    if (end == word.c_str() || *end != '\0' || !std::isfinite(v))
      fail(std::string(what) + " is not a finite number: '" + word + "'");
    return v;
  }

  void point(std::istringstream& in)
  {
    const double x = number(in, "x"), y = number(in, "y"), z = number(in, "z");
    mesh.points.push_back({ x, y, z });
  }

  /// A face of corners (0-based indices), as a fan from its first corner.
  void face(const std::vector<long long>& corners)
  {
    if (corners.size() < 3)
      fail("a face has " + std::to_string(corners.size()) + " corner(s), fewer than 3");
    for (long long c : corners)
      if (c < 0 || c >= static_cast<long long>(mesh.points.size()))
        fail("a face uses vertex " + std::to_string(c + 1) + " of " +
          std::to_string(mesh.points.size()) + " read so far");
    for (std::size_t i = 1; i + 1 < corners.size(); ++i)
      mesh.triangles.push_back({ static_cast<std::uint32_t>(corners[0]),
        static_cast<std::uint32_t>(corners[i]), static_cast<std::uint32_t>(corners[i + 1]) });
  }

  bool next(std::istream& in)
  {
    while (std::getline(in, text))
    {
      ++line;
      if (!text.empty() && text.back() == '\r')
        text.pop_back();
      const std::size_t first = text.find_first_not_of(" \t");
      if (first != std::string::npos && text[first] != '#')
        return true;
    }
    return false;
  }

  void readObj(std::istream& in)
  {
    while (next(in))
    {
      std::istringstream words(text);
      std::string key;
      words >> key;
      if (key == "v")
        point(words);
      else if (key == "f")
      {
        // v, v/vt, v//vn or v/vt/vn; 1-based, or negative: counted back from the last vertex.
        std::vector<long long> corners;
        std::string corner;
        while (words >> corner)
        {
          char* end = nullptr;
          const long long k = std::strtoll(corner.c_str(), &end, 10);
          if (end == corner.c_str() || (*end != '\0' && *end != '/') || k == 0)
            fail("a face corner is not a vertex index: '" + corner + "'");
          corners.push_back(k > 0 ? k - 1 : static_cast<long long>(mesh.points.size()) + k);
        }
        face(corners);
      }
      // vt, vn, g, o, s, usemtl, mtllib, l, ...: not part of a triangle surface.
    }
  }

  long long count(std::istringstream& in, const char* what)
  {
    const double v = number(in, what);
    if (v < 0 || v != std::floor(v) || v > 1e9)
      fail(std::string(what) + " must be a whole number >= 0");
    return static_cast<long long>(v);
  }

  void readOff(std::istream& in)
  {
    if (!next(in))
      fail("an empty file (an .off file starts with OFF)");
    std::istringstream header(text);
    std::string magic;
    header >> magic;
    if (magic != "OFF")
      fail("an .off file starts with OFF, not '" + magic + "'");
    // The counts may follow OFF on its line or stand on the next.
    std::string rest;
    std::getline(header, rest);
    if (rest.find_first_not_of(" \t") == std::string::npos)
    {
      if (!next(in))
        fail("missing the vertex, face and edge counts");
      rest = text;
    }
    std::istringstream counts(rest);
    const long long vertices = count(counts, "the vertex count");
    const long long faces = count(counts, "the face count");
    for (long long i = 0; i < vertices; ++i)
    {
      if (!next(in))
        fail("the file ends after " + std::to_string(i) + " of " + std::to_string(vertices) +
          " vertices");
      std::istringstream words(text);
      point(words);
    }
    for (long long i = 0; i < faces; ++i)
    {
      if (!next(in))
        fail(
          "the file ends after " + std::to_string(i) + " of " + std::to_string(faces) + " faces");
      std::istringstream words(text);
      const long long n = count(words, "the face's corner count");
      std::vector<long long> corners;
      for (long long k = 0; k < n; ++k)
        corners.push_back(count(words, "a face corner"));
      face(corners);
    }
  }

  /// The index of a corner point, the same for equal coordinates: .stl repeats a triangle's
  /// corners, and only shared points make its triangles one surface.
  std::map<std::array<double, 3>, std::uint32_t> welded;
  long long weld(double x, double y, double z)
  {
    const auto [it, added] = welded.emplace(
      std::array<double, 3>{ x, y, z }, static_cast<std::uint32_t>(mesh.points.size()));
    if (added)
      mesh.points.push_back({ x, y, z });
    return it->second;
  }

  void readStl(std::istream& in)
  {
    // Binary: an 80-byte header, a little-endian uint32 count, then 50 bytes a triangle (the
    // normal and three corners as float32, a uint16). A file of exactly that size is binary even
    // when its header starts with "solid", as many exporters write; any other is ASCII.
    in.seekg(0, std::ios::end);
    const auto size = static_cast<unsigned long long>(in.tellg());
    in.seekg(0);
    if (size >= 84)
    {
      unsigned char head[84];
      in.read(reinterpret_cast<char*>(head), 84);
      const unsigned long long n = static_cast<unsigned long long>(head[80]) |
        static_cast<unsigned long long>(head[81]) << 8 |
        static_cast<unsigned long long>(head[82]) << 16 |
        static_cast<unsigned long long>(head[83]) << 24;
      if (84 + 50 * n == size)
      {
        for (unsigned long long i = 0; i < n; ++i)
        {
          unsigned char t[50];
          in.read(reinterpret_cast<char*>(t), 50);
          std::vector<long long> corners;
          for (int c = 0; c < 3; ++c)
          {
            double v[3];
            for (int k = 0; k < 3; ++k)
              v[k] = littleEndianFloat(t + 12 + 12 * c + 4 * k);
            if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
              fail("triangle " + std::to_string(i + 1) + " has a corner that is not finite");
            corners.push_back(weld(v[0], v[1], v[2]));
          }
          face(corners);
        }
        return;
      }
      in.seekg(0);
    }
    if (!next(in))
      fail("an empty file (an ASCII .stl file starts with solid)");
    std::string key;
    std::istringstream(text) >> key;
    if (key != "solid")
      fail("an .stl file is binary (84 + 50 bytes a triangle) or ASCII starting with solid, "
           "not '" +
        key + "'");
    std::vector<long long> corners;
    bool inLoop = false;
    while (next(in))
    {
      std::istringstream words(text);
      words >> key;
      if (key == "outer")
      {
        inLoop = true;
        corners.clear();
      }
      else if (key == "vertex")
      {
        if (!inLoop)
          fail("a vertex outside an outer loop");
        const double x = number(words, "x"), y = number(words, "y"), z = number(words, "z");
        corners.push_back(weld(x, y, z));
      }
      else if (key == "endloop")
      {
        face(corners);
        inLoop = false;
      }
      else if (key == "endsolid")
        return;
      else if (key != "facet" && key != "endfacet")
        fail("unexpected '" + key + "' in an ASCII .stl file");
    }
  }

  static double littleEndianFloat(const unsigned char* b)
  {
    const std::uint32_t u = static_cast<std::uint32_t>(b[0]) |
      static_cast<std::uint32_t>(b[1]) << 8 | static_cast<std::uint32_t>(b[2]) << 16 |
      static_cast<std::uint32_t>(b[3]) << 24;
    float f;
    std::memcpy(&f, &u, 4);
    return f;
  }

  /// A .ply property: a scalar, or a list (its count's type, then its items' type).
  struct PlyProperty
  {
    std::string name;
    std::string type;
    std::string countType; ///< empty for a scalar
  };
  struct PlyElement
  {
    std::string name;
    long long count = 0;
    std::vector<PlyProperty> properties;
  };

  static int plySize(const std::string& type)
  {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8")
      return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16")
      return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
      return 4;
    if (type == "double" || type == "float64")
      return 8;
    return 0;
  }

  /// One binary .ply value of `type` (plySize known), in the file's byte order.
  double plyBinary(std::istream& in, const std::string& type, bool bigEndian)
  {
    unsigned char b[8];
    const int n = plySize(type);
    if (!in.read(reinterpret_cast<char*>(b), n))
      fail("the file ends inside its data");
    if (bigEndian)
      std::reverse(b, b + n);
    auto as = [&](auto v)
    {
      std::memcpy(&v, b, sizeof v);
      return static_cast<double>(v);
    };
    if (type == "char" || type == "int8")
      return as(std::int8_t{});
    if (type == "uchar" || type == "uint8")
      return as(std::uint8_t{});
    if (type == "short" || type == "int16")
      return as(std::int16_t{});
    if (type == "ushort" || type == "uint16")
      return as(std::uint16_t{});
    if (type == "int" || type == "int32")
      return as(std::int32_t{});
    if (type == "uint" || type == "uint32")
      return as(std::uint32_t{});
    if (type == "float" || type == "float32")
      return as(float{});
    return as(double{});
  }

  void readPly(std::istream& in)
  {
    if (!next(in) || text != "ply")
      fail("a .ply file starts with ply");
    std::string format;
    std::vector<PlyElement> elements;
    for (;;)
    {
      if (!next(in))
        fail("the header has no end_header");
      std::istringstream words(text);
      std::string key;
      words >> key;
      if (key == "end_header")
        break;
      if (key == "format")
      {
        words >> format;
        if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
          fail("unknown .ply format '" + format + "'");
      }
      else if (key == "element")
      {
        PlyElement e;
        words >> e.name;
        e.count = count(words, "the element count");
        elements.push_back(e);
      }
      else if (key == "property")
      {
        if (elements.empty())
          fail("a property before any element");
        PlyProperty p;
        words >> p.type;
        if (p.type == "list")
          words >> p.countType >> p.type;
        words >> p.name;
        if (plySize(p.type) == 0 || (!p.countType.empty() && plySize(p.countType) == 0))
          fail("unknown .ply property type in '" + text + "'");
        elements.back().properties.push_back(p);
      }
      else if (key != "comment" && key != "obj_info")
        fail("unexpected '" + key + "' in a .ply header");
    }
    if (format.empty())
      fail("the header has no format line");
    const bool ascii = format == "ascii", bigEndian = format == "binary_big_endian";
    std::istringstream words;
    // The next value: ASCII ones are read a line (one element) at a time.
    auto value = [&](const std::string& type, const char* what)
    {
      return ascii ? number(words, what) : plyBinary(in, type, bigEndian);
    };
    for (const PlyElement& e : elements)
    {
      const bool vertex = e.name == "vertex", faces = e.name == "face";
      for (long long i = 0; i < e.count; ++i)
      {
        if (ascii)
        {
          if (!next(in))
            fail("the file ends after " + std::to_string(i) + " of " + std::to_string(e.count) +
              " " + e.name + " elements");
          words.clear();
          words.str(text);
        }
        double xyz[3] = { 0, 0, 0 };
        int seen = 0;
        for (const PlyProperty& p : e.properties)
        {
          if (p.countType.empty())
          {
            const double v = value(p.type, p.name.c_str());
            const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
            if (vertex && axis >= 0)
            {
              if (!std::isfinite(v))
                fail("vertex " + std::to_string(i) + " has a coordinate that is not finite");
              xyz[axis] = v;
              seen |= 1 << axis;
            }
            continue;
          }
          const double n = value(p.countType, "a list's count");
          if (n < 0 || n != std::floor(n) || n > 1e6)
            fail("a list's count must be a whole number >= 0");
          std::vector<long long> items;
          for (long long k = 0; k < static_cast<long long>(n); ++k)
            items.push_back(static_cast<long long>(value(p.type, "a list item")));
          if (faces && (p.name == "vertex_indices" || p.name == "vertex_index"))
            face(items);
        }
        if (vertex)
        {
          if (seen != 7)
            fail("the vertex element has no x, y and z properties");
          mesh.points.push_back({ xyz[0], xyz[1], xyz[2] });
        }
      }
    }
  }
};

} // namespace

bool isMeshFile(const std::string& path)
{
  return endsWith(path, ".obj") || endsWith(path, ".off") || endsWith(path, ".ply") ||
    endsWith(path, ".stl");
}

complex::ExplicitGeometry readMeshFile(const std::string& path)
{
  Reader r;
  r.path = path;
  // Read whole first, so that a file cut short or replaced while it is read is refused rather
  // than read as a smaller mesh (readSourceFile compares its size with the bytes read). A mesh
  // file is bounded by memory only, as the mesh made of it is.
  Limits whole;
  whole.maxFileBytes = std::size_t(1) << 34;
  std::istringstream in(readSourceFile(path, whole));
  if (endsWith(path, ".off"))
    r.readOff(in);
  else if (endsWith(path, ".obj"))
    r.readObj(in);
  else if (endsWith(path, ".ply"))
    r.readPly(in);
  else if (endsWith(path, ".stl"))
    r.readStl(in);
  else
    r.fail("a mesh file is .obj, .off, .ply or .stl");
  if (r.mesh.triangles.empty())
  {
    r.line = 0;
    r.text.clear();
    r.fail("has no faces (a mesh shape is a triangle surface)");
  }
  return std::move(r.mesh);
}

} // namespace ictk::lang
