// SPDX-License-Identifier: BSD-3-Clause
// Model files by extension. Bounds are {xmin, xmax, ymin, ymax, zmin, zmax} (VTK's order); only
// FRep XML stores them.
#include "Lang/ModelFile.h"

#include "Lang/BlobReader.h"
#include "Lang/FRepXml.h"
#include "Lang/HyperFun.h"
#include "Lang/Scene.h"
#include "Lang/VmReader.h"

#include "FRep/Bounds.h"
#include "FRep/Tape.h"

#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace ictk::lang
{

namespace
{
enum class Format
{
  Unknown,
  HyperFun,
  Xml,
  Vm,
  Scene,
  Blob
};

Format formatOf(const std::string& path)
{
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (ext == ".hf")
  {
    return Format::HyperFun;
  }
  if (ext == ".xml")
  {
    return Format::Xml;
  }
  if (ext == ".vm")
  {
    return Format::Vm;
  }
  if (ext == ".scn" || ext == ".scene")
  {
    return Format::Scene;
  }
  if (ext == ".blob")
  {
    return Format::Blob;
  }
  return Format::Unknown;
}

[[noreturn]] void unknownExtension(const std::string& path)
{
  throw std::invalid_argument("'" + path +
    "' is not a model file: the extension must be .hf (HyperFun), .xml (FRep XML), .scn (a "
    "scene), .vm (Fidget SSA, read only) or .blob (BlobTree, read only)");
}

// A HyperFun body name made from any model name: letters, digits and '_', starting with a letter.
std::string hyperFunName(const std::string& name)
{
  std::string s;
  for (char c : name)
  {
    const auto u = static_cast<unsigned char>(c);
    s += (u < 0x80 && (std::isalnum(u) || c == '_')) ? c : '_';
  }
  if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0])))
  {
    s = "model_" + s;
  }
  if (s.size() > 100)
  {
    s.resize(100);
  }
  return s;
}

std::string hyperFunText(const ModelFile& model)
{
  const std::string name = hyperFunName(model.name.empty() ? "model" : model.name);
  try
  {
    return writeHyperFun(model.model, name, model.parameterCount);
  }
  catch (const std::invalid_argument&)
  {
    // A reserved name (a keyword, a built-in, hf..., v<n>): any prefix the writer accepts will do.
    return writeHyperFun(model.model, "model_" + name, model.parameterCount);
  }
}

[[noreturn]] void saveError(const std::string& path, const std::string& what, int err)
{
  throw std::runtime_error("cannot save '" + path + "': " + what +
    (err ? std::string(": ") + std::strerror(err) : std::string()));
}

// Writes `text` next to `path` and renames it over `path`: readers see the old file or the new
// one, never a truncated one, even if this process dies half-way.
void writeAtomically(const std::string& path, const std::string& text)
{
  static std::atomic<unsigned> counter{ 0 };
  const std::filesystem::path target(path);
  const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  const std::string temp = (target.parent_path() /
    ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
      std::to_string(counter++) + "-" + std::to_string(stamp % 1000000)))
                             .string();
  // 0666 and the umask, as for any new file; an existing file keeps its mode.
  int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0)
  {
    saveError(path, "cannot create the temporary file '" + temp + "'", errno);
  }
  struct stat existing;
  if (::stat(path.c_str(), &existing) == 0)
  {
    (void)::fchmod(fd, existing.st_mode & 07777);
  }
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0)
  {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR)
    {
      continue;
    }
    if (n <= 0)
    {
      const int err = errno;
      ::close(fd);
      ::unlink(temp.c_str());
      saveError(path, "cannot write the temporary file", err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  // The data must be on disk before the rename makes it the file, or a crash could leave an
  // empty file under the final name.
  if (::fsync(fd) != 0 || ::close(fd) != 0)
  {
    const int err = errno;
    ::unlink(temp.c_str());
    saveError(path, "cannot write the temporary file", err);
  }
  if (::rename(temp.c_str(), path.c_str()) != 0)
  {
    const int err = errno;
    ::unlink(temp.c_str());
    saveError(path, "cannot rename the temporary file over it", err);
  }
}
} // namespace

bool isModelFile(const std::string& path)
{
  return formatOf(path) != Format::Unknown;
}

bool isBlobFile(const std::string& path)
{
  return formatOf(path) == Format::Blob;
}

BlobModelFile loadBlobModelFile(const std::string& path, const Limits& limits)
{
  BlobModelFile blob;
  blob.name = std::filesystem::path(path).stem().string();
  blob.tree = readBlobFile(path, limits, &blob.origins);
  return blob;
}

ModelFile BlobModelFile::at(double t) const
{
  // The tree's field mapped to f >= 0 inside (frep::blob::shape); the bounds are the instance's
  // support box, where every element's field vanishes, with a 2 % margin.
  const frep::blob::BlobTree instance = this->instance(t);
  const auto box = frep::blob::supportBox(instance);
  std::array<double, 6> bounds{};
  for (int a = 0; a < 3; ++a)
  {
    const double pad = 0.02 * (box[1][a] - box[0][a]);
    bounds[2 * a] = box[0][a] - pad;
    bounds[2 * a + 1] = box[1][a] + pad;
  }
  // Texture nodes (material, marble, wood, granite) make a TextureTree: its colour and optics
  // become the model's attributes.
  bool textured = false;
  for (const frep::blob::Node& n : instance.nodes())
  {
    textured = textured || frep::blob::isTexture(n.kind);
  }
  if (textured)
  {
    return ModelFile{ name, 0, frep::blob::texturedHypervolume(instance), bounds };
  }
  return ModelFile{ name, 0, frep::Hypervolume(frep::blob::shape(instance).withLabel(name)),
    bounds };
}

bool isSceneFile(const std::string& path)
{
  return formatOf(path) == Format::Scene;
}

ModelFile loadModelFile(
  const std::string& path, const Limits& limits, const std::vector<double>& parameterValues)
{
  switch (formatOf(path))
  {
    case Format::HyperFun:
    {
      HyperFunModel hf = readHyperFunFile(path, {}, limits, parameterValues);
      return ModelFile{ std::move(hf.name), hf.parameterCount, std::move(hf.model), std::nullopt };
    }
    case Format::Vm:
    {
      // Fidget's SSA benchmark models (read only): negated on import, 2D unless z is used.
      VmModel vm = readVmFile(path, limits);
      const frep::Domain domain = (vm.axesUsed & 4u) ? frep::Domain::XYZ : frep::Domain::XY;
      std::string name = std::filesystem::path(path).stem().string();
      return ModelFile{ name, 0,
        frep::Hypervolume(frep::Shape(std::move(vm.function), domain, name)), std::nullopt };
    }
    case Format::Scene:
    {
      // Seed 003's scenes (Lang/Scene.h): the solid with its "object" ids and colours.
      BuiltScene scene = buildScene(readSceneFile(path, limits));
      return ModelFile{ std::filesystem::path(path).stem().string(), 0, std::move(scene.model),
        std::nullopt };
    }
    case Format::Blob:
    {
      // A model file read without a time has no instant to instantiate an animated tree at, and
      // its t = 0 instance would be a silent answer to a question about another time: refused.
      const BlobModelFile blob = loadBlobModelFile(path, limits);
      if (blob.animated())
      {
        throw std::invalid_argument("'" + path +
          "' is an animated BlobTree: it is a model only at a time t (`ictk eval`, `sample`, "
          "`mesh` and `render` instantiate it with --time t or --frames T0:T1:DT; in C++, "
          "lang::loadBlobModelFile(path).at(t); docs/blobtree.md)");
      }
      return blob.at(0.0);
    }
    case Format::Xml:
    {
      // readFRepXmlFile's checks (readable, size) first, then the full document.
      std::string text;
      {
        std::error_code ec;
        const auto size = std::filesystem::file_size(path, ec);
        if (!ec && size > limits.maxFileBytes)
        {
          Diagnostic d;
          d.where.file = path;
          d.message = "the file has " + std::to_string(size) + " bytes, more than the limit of " +
            std::to_string(limits.maxFileBytes);
          throw ParseError({ d });
        }
        FILE* f = std::fopen(path.c_str(), "rb");
        if (!f)
        {
          Diagnostic d;
          d.where.file = path;
          d.message = "cannot open the file: " + std::string(std::strerror(errno));
          throw ParseError({ d });
        }
        char buf[65536];
        std::size_t n;
        while ((n = std::fread(buf, 1, sizeof buf, f)) > 0)
        {
          text.append(buf, n);
          if (text.size() > limits.maxFileBytes)
          {
            break;
          }
        }
        const bool failed = std::ferror(f);
        std::fclose(f);
        if (failed)
        {
          Diagnostic d;
          d.where.file = path;
          d.message = "cannot read the file";
          throw ParseError({ d });
        }
      }
      FRepXmlDocument doc = readFRepXmlDocument(text, path, limits);
      std::string name =
        doc.name.empty() ? std::filesystem::path(path).stem().string() : std::move(doc.name);
      return ModelFile{ std::move(name), doc.parameterCount, std::move(*doc.model), doc.bounds };
    }
    default:
      unknownExtension(path);
  }
}

void saveSceneFile(const std::string& input, const std::string& path, const Limits& limits)
{
  writeAtomically(path, writeScene(readSceneFile(input, limits)));
}

void saveBlobFile(const BlobModelFile& blob, const std::string& path, std::optional<double> time)
{
  if (formatOf(path) != Format::Blob)
  {
    throw std::invalid_argument("cannot save '" + path + "' as a BlobTree: it is not a .blob file");
  }
  if (time && !std::isfinite(*time))
  {
    throw std::invalid_argument("cannot save '" + path + "': the time is not a finite number");
  }
  writeAtomically(path, writeBlob(time ? blob.instance(*time) : blob.tree));
}

void saveModelFile(const ModelFile& model, const std::string& path)
{
  std::string text;
  switch (formatOf(path))
  {
    case Format::HyperFun:
      text = hyperFunText(model);
      break;
    case Format::Xml:
      text = writeFRepXmlDocument(
        model.model, model.name.empty() ? "model" : model.name, model.parameterCount, model.bounds);
      break;
    case Format::Vm:
      throw std::invalid_argument("cannot save '" + path + "': .vm files are read only");
    case Format::Scene:
      throw std::invalid_argument("cannot save '" + path +
        "': a scene is written only from a scene (saveSceneFile; `ictk convert in.scn out.scn`)");
    case Format::Blob:
      // A hypervolume is an expression: the skeletal elements and operators of a BlobTree
      // cannot be recovered from it.
      throw std::invalid_argument("cannot save '" + path +
        "': a .blob is written only from a BlobTree (saveBlobFile; `ictk convert in.blob "
        "out.blob`), not from a hypervolume");
    default:
      unknownExtension(path);
  }
  writeAtomically(path, text);
}

std::array<double, 6> modelFileBounds(const ModelFile& file, const std::vector<double>& parameters)
{
  if (file.bounds)
  {
    return *file.bounds;
  }
  constexpr double searchHalfWidth = 10.0;
  const frep::Box search{ { -searchHalfWidth, -searchHalfWidth, -searchHalfWidth },
    { searchHalfWidth, searchHalfWidth, searchHalfWidth } };
  std::vector<double> values = parameters;
  values.resize(std::max(values.size(), static_cast<std::size_t>(file.parameterCount)), 0.0);
  std::optional<frep::Box> box;
  try
  {
    box = frep::boundingBox(
      frep::Tape::compile(file.model.geometry().function()), search, 6, 0.0, values);
  }
  catch (const std::invalid_argument&)
  {
    box = search;
  }
  const frep::Box b = box ? *box : search;
  const std::uint8_t axes = frep::domainAxes(file.model.geometry().domain());
  std::array<double, 6> bounds{};
  for (int a = 0; a < 3; ++a)
  {
    const bool used = axes & (1u << a);
    // A little margin, so the surface does not touch the grid's border.
    const double pad = 0.02 * (b.hi[a] - b.lo[a]);
    bounds[2 * a] = used ? b.lo[a] - pad : 0.0;
    bounds[2 * a + 1] = used ? b.hi[a] + pad : 0.0;
  }
  return bounds;
}

} // namespace ictk::lang
