// SPDX-License-Identifier: BSD-3-Clause
// .obj and .off triangle meshes (MeshFile.h): a line-by-line reader of vertices and faces.
#include "Lang/MeshFile.h"

#include "Lang/Diagnostics.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
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
};

} // namespace

bool isMeshFile(const std::string& path)
{
  return endsWith(path, ".obj") || endsWith(path, ".off");
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
  else
    r.fail("a mesh file is .obj or .off");
  if (r.mesh.triangles.empty())
  {
    r.line = 0;
    r.text.clear();
    r.fail("has no faces (a mesh shape is a triangle surface)");
  }
  return std::move(r.mesh);
}

} // namespace ictk::lang
