// SPDX-License-Identifier: BSD-3-Clause
#include "Voxel/VolumeFile.h"

#include "Voxel/VdbIO.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>

namespace ictk::voxel
{
namespace
{

bool endsWith(const std::string& s, const std::string& tail)
{
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string quoted(const std::string& path)
{
  return "'" + path + "'";
}

/// The whole gzip stream of `path`, inflated; a stream that stops before its end is an error
/// (a truncated download or copy), not a short scan, and so is one that inflates to more than
/// `limit` bytes.
std::string gunzip(const std::string& path, std::uint64_t limit)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    throw std::runtime_error(quoted(path) + ": no such file or not readable");
  }
  const std::string packed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (packed.size() < 2 || static_cast<unsigned char>(packed[0]) != 0x1f ||
    static_cast<unsigned char>(packed[1]) != 0x8b)
  {
    throw std::runtime_error(
      quoted(path) + ": not an InVesalius project (an .inv3 file is gzip-compressed)");
  }
  z_stream z{};
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK)
  {
    throw std::runtime_error(quoted(path) + ": zlib could not start inflating");
  }
  std::string out;
  out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(limit, packed.size() * 3)));
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(packed.data()));
  z.avail_in = static_cast<uInt>(packed.size());
  int status = Z_OK;
  std::size_t produced = 0;
  while (status == Z_OK)
  {
    if (produced == out.size())
    {
      if (produced >= limit)
      {
        inflateEnd(&z);
        throw std::runtime_error(quoted(path) + ": the archive inflates to more than " +
          std::to_string(limit) + " bytes (damaged, or not a scan ICTK should hold in memory)");
      }
      out.resize(static_cast<std::size_t>(
        std::min<std::uint64_t>(limit, std::max<std::uint64_t>(2 * out.size(), 1024))));
    }
    z.next_out = reinterpret_cast<Bytef*>(&out[produced]);
    z.avail_out = static_cast<uInt>(out.size() - produced);
    status = inflate(&z, Z_NO_FLUSH);
    produced = out.size() - z.avail_out;
    if (status == Z_BUF_ERROR && z.avail_in == 0)
    {
      break;
    }
    if (status == Z_BUF_ERROR)
    {
      status = Z_OK; // the output was full: grow and go on
    }
  }
  const std::string message = z.msg ? z.msg : "";
  inflateEnd(&z);
  if (status != Z_STREAM_END)
  {
    throw std::runtime_error(quoted(path) +
      (status == Z_BUF_ERROR
          ? ": the gzip data is truncated (the file was cut short)"
          : ": corrupt gzip data" + (message.empty() ? "" : " (" + message + ")")));
  }
  out.resize(produced);
  return out;
}

/// The regular files of a tar archive by their base name (the folder InVesalius wrote them in
/// varies from file to file).
std::map<std::string, std::string> untar(const std::string& tar, const std::string& path)
{
  std::map<std::string, std::string> files;
  std::size_t at = 0;
  std::string longName;
  while (at + 512 <= tar.size())
  {
    const char* h = tar.data() + at;
    if (std::all_of(h, h + 512, [](char c) { return c == 0; }))
    {
      break;
    }
    std::string name(h, strnlen(h, 100));
    const std::string prefix(h + 345, strnlen(h + 345, 155));
    if (std::memcmp(h + 257, "ustar", 5) == 0 && !prefix.empty())
    {
      name = prefix + "/" + name;
    }
    std::size_t size = 0;
    for (int i = 124; i < 136 && h[i]; ++i)
    {
      if (h[i] == ' ')
      {
        continue;
      }
      if (h[i] < '0' || h[i] > '7')
      {
        throw std::runtime_error(quoted(path) +
          ": the tar archive inside is corrupt (a bad size "
          "field at byte " +
          std::to_string(at + 124) + ")");
      }
      size = size * 8 + static_cast<std::size_t>(h[i] - '0');
    }
    const char type = h[156];
    at += 512;
    if (at + size > tar.size())
    {
      throw std::runtime_error(quoted(path) + ": the tar archive inside is truncated ('" + name +
        "' needs " + std::to_string(size) + " bytes, " + std::to_string(tar.size() - at) +
        " remain)");
    }
    if (type == 'L')
    {
      longName.assign(tar.data() + at, strnlen(tar.data() + at, size));
    }
    else
    {
      if (!longName.empty())
      {
        name = longName;
        longName.clear();
      }
      if (type == '0' || type == '\0')
      {
        const std::size_t slash = name.rfind('/');
        files[slash == std::string::npos ? name : name.substr(slash + 1)] = tar.substr(at, size);
      }
    }
    at += (size + 511) / 512 * 512;
  }
  return files;
}

/// An Apple XML property list value (only what InVesalius writes).
struct Plist
{
  std::string type; // dict, array, string, integer, real, true, false
  std::string text;
  std::vector<Plist> items;
  std::vector<std::string> keys; // dict: keys[i] names items[i]

  const Plist* find(const std::string& key) const
  {
    for (std::size_t i = 0; i < keys.size(); ++i)
    {
      if (keys[i] == key)
      {
        return &items[i];
      }
    }
    return nullptr;
  }
};

class PlistParser
{
public:
  PlistParser(const std::string& text, const std::string& where)
    : text_(text)
    , where_(where)
  {
  }

  Plist parse()
  {
    std::string tag = next();
    while (tag.rfind("?", 0) == 0 || tag.rfind("!", 0) == 0 || tag.rfind("plist", 0) == 0)
    {
      tag = next();
    }
    return value(tag);
  }

private:
  /// The next tag's inside (between '<' and '>'), skipping text.
  std::string next()
  {
    const std::size_t open = text_.find('<', at_);
    const std::size_t close = open == std::string::npos ? open : text_.find('>', open);
    if (close == std::string::npos)
    {
      fail("unexpected end");
    }
    at_ = close + 1;
    return text_.substr(open + 1, close - open - 1);
  }

  std::string textUntil(const std::string& tag)
  {
    const std::string end = "</" + tag + ">";
    const std::size_t stop = text_.find(end, at_);
    if (stop == std::string::npos)
    {
      fail("<" + tag + "> is not closed");
    }
    std::string t = text_.substr(at_, stop - at_);
    at_ = stop + end.size();
    return t;
  }

  Plist value(std::string tag)
  {
    Plist v;
    const bool empty = !tag.empty() && tag.back() == '/';
    if (empty)
    {
      tag.pop_back();
    }
    v.type = tag;
    if (tag == "true" || tag == "false" || empty)
    {
      return v;
    }
    if (tag == "string" || tag == "integer" || tag == "real" || tag == "date" || tag == "data")
    {
      v.text = textUntil(tag);
      return v;
    }
    if (tag != "dict" && tag != "array")
    {
      fail("unexpected <" + tag + ">");
    }
    for (std::string t = next(); t != "/" + tag; t = next())
    {
      if (tag == "dict")
      {
        if (t != "key")
        {
          fail("a <dict> entry without <key>");
        }
        v.keys.push_back(textUntil("key"));
        t = next();
      }
      v.items.push_back(value(t));
    }
    return v;
  }

  [[noreturn]] void fail(const std::string& what) const
  {
    throw std::runtime_error(
      where_ + ": malformed property list (" + what + " near byte " + std::to_string(at_) + ")");
  }

  const std::string& text_;
  std::string where_;
  std::size_t at_ = 0;
};

double plistNumber(const Plist* v, const std::string& where)
{
  if (!v || (v->type != "integer" && v->type != "real"))
  {
    throw std::runtime_error(where + " is not a number");
  }
  try
  {
    std::size_t used = 0;
    const double x = std::stod(v->text, &used);
    if (used != v->text.size() || !std::isfinite(x))
    {
      throw std::invalid_argument(v->text);
    }
    return x;
  }
  catch (const std::exception&)
  {
    throw std::runtime_error(where + " is not a finite number ('" + v->text + "')");
  }
}

template <typename T>
void convert(const std::string& raw, std::vector<float>& out)
{
  for (std::size_t i = 0; i < out.size(); ++i)
  {
    T x;
    std::memcpy(&x, raw.data() + i * sizeof(T), sizeof(T)); // little-endian hosts only (x86, arm)
    out[i] = static_cast<float>(x);
  }
}

} // namespace

bool isCoreVolume(const std::string& path)
{
  return endsWith(path, ".vdb") || endsWith(path, ".inv3");
}

std::shared_ptr<VoxelGrid> readCoreVolume(const std::string& path, const std::string& array)
{
  if (endsWith(path, ".vdb"))
  {
    return readVdb(path, array);
  }
  if (endsWith(path, ".inv3"))
  {
    return readInv3(path, array);
  }
  throw std::invalid_argument(
    quoted(path) + ": the core reads .vdb and .inv3 volumes (others through the VTK layer)");
}

std::shared_ptr<VoxelGrid> readInv3(
  const std::string& path, const std::string& array, std::uint64_t maxInflatedBytes)
{
  if (!array.empty() && array != "matrix")
  {
    throw std::runtime_error(
      quoted(path) + ": an InVesalius project has one scan, \"matrix\" (not '" + array + "')");
  }
  const auto files = untar(gunzip(path, maxInflatedBytes), path);
  const auto mainPlist = files.find("main.plist");
  if (mainPlist == files.end())
  {
    throw std::runtime_error(
      quoted(path) + ": no main.plist in the archive (not an InVesalius project)");
  }
  const std::string where = quoted(path) + ": main.plist";
  const Plist root = PlistParser(mainPlist->second, where).parse();
  const Plist* matrix = root.find("matrix");
  const Plist* dtype = matrix ? matrix->find("dtype") : nullptr;
  const Plist* fileName = matrix ? matrix->find("filename") : nullptr;
  const Plist* shape = matrix ? matrix->find("shape") : nullptr;
  const Plist* spacing = root.find("spacing");
  if (!dtype || !fileName || !shape || shape->items.size() != 3)
  {
    throw std::runtime_error(where +
      " has no \"matrix\" with \"dtype\", \"filename\" and a "
      "three-number \"shape\"");
  }
  if (!spacing || spacing->items.size() != 3)
  {
    throw std::runtime_error(where + " has no three-number \"spacing\"");
  }
  auto grid = std::make_shared<VoxelGrid>();
  for (int a = 0; a < 3; ++a)
  {
    // shape is numpy's (nz, ny, nx); spacing is (sx, sy, sz).
    const double n = plistNumber(&shape->items[static_cast<std::size_t>(2 - a)],
      where + ": matrix shape[" + std::to_string(2 - a) + "]");
    if (n < 2 || n > 1e6 || n != std::floor(n))
    {
      throw std::runtime_error(where + ": matrix shape[" + std::to_string(2 - a) +
        "] must be a whole number of at least 2");
    }
    grid->dimensions[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(n);
    grid->spacing[static_cast<std::size_t>(a)] = plistNumber(
      &spacing->items[static_cast<std::size_t>(a)], where + ": spacing[" + std::to_string(a) + "]");
  }
  const std::string& type = dtype->text;
  const std::size_t bytes = type == "int16" || type == "uint16" ? 2
    : type == "int8" || type == "uint8"                         ? 1
    : type == "float32"                                         ? 4
                                                                : 0;
  if (bytes == 0)
  {
    throw std::runtime_error(
      where + ": matrix dtype '" + type + "' is not one of int16, uint16, int8, uint8, float32");
  }
  const auto data = files.find(fileName->text);
  if (data == files.end())
  {
    throw std::runtime_error(
      quoted(path) + ": the archive has no '" + fileName->text + "' (main.plist's matrix)");
  }
  const std::size_t count = static_cast<std::size_t>(grid->pointCount());
  if (data->second.size() != count * bytes)
  {
    throw std::runtime_error(quoted(path) + ": '" + fileName->text + "' holds " +
      std::to_string(data->second.size()) + " bytes; its shape " +
      std::to_string(grid->dimensions[2]) + " x " + std::to_string(grid->dimensions[1]) + " x " +
      std::to_string(grid->dimensions[0]) + " of " + type + " needs " +
      std::to_string(count * bytes));
  }
  grid->values.resize(count);
  if (type == "int16")
  {
    convert<std::int16_t>(data->second, grid->values);
  }
  else if (type == "uint16")
  {
    convert<std::uint16_t>(data->second, grid->values);
  }
  else if (type == "int8")
  {
    convert<std::int8_t>(data->second, grid->values);
  }
  else if (type == "uint8")
  {
    convert<std::uint8_t>(data->second, grid->values);
  }
  else
  {
    convert<float>(data->second, grid->values);
  }
  validate(*grid, quoted(path));
  return grid;
}

} // namespace ictk::voxel
