// SPDX-License-Identifier: BSD-3-Clause
// The complex file reader: one Reader class over the whole document (cells of every kind,
// attributes, relations), its parts sharing the reader's diagnostics and HyperFun library, which
// is why it runs past a thousand lines.
#include "Lang/ComplexFile.h"

#include "FRep/FieldOperations.h"
#include "FRep/Tape.h"
#include "Lang/HyperFun.h"
#include "Voxel/VolumeFile.h"
#include "Voxel/VoxelField.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

namespace ictk::lang
{
namespace
{

using complex::Cell;
using complex::CellKind;
using complex::Complex;
using frep::Box3;
using frep::FieldPtr;
using frep::Point3;
using Json = nlohmann::json;

/// An error at a known place; collected, then thrown together as a ParseError.
struct Problem
{
  std::string message;
  std::size_t offset = std::string::npos;
};

class Reader
{
public:
  Reader(const std::string& text, const std::string& fileName, const Limits& limits,
    const ComplexFileReaders& readers)
    : text_(text)
    , file_(fileName)
    , limits_(limits)
    , readers_(readers)
  {
  }

  Complex read()
  {
    Json doc;
    try
    {
      doc = Json::parse(text_);
    }
    catch (const Json::parse_error& e)
    {
      // nlohmann reports the byte after the error; point at the byte itself.
      report(std::string("invalid JSON: ") + jsonMessage(e.what()), e.byte > 0 ? e.byte - 1 : 0);
      throwIfFailed();
    }
    catch (const Json::out_of_range& e)
    {
      // A number beyond double's range ("number overflow parsing '1e99999'", found by
      // FuzzComplexJson): reported at the number, which the message quotes.
      const std::string what = jsonMessage(e.what());
      const auto open = what.find('\'');
      const auto close = open == std::string::npos ? open : what.find('\'', open + 1);
      const std::size_t at = close == std::string::npos
        ? std::string::npos
        : text_.find(what.substr(open + 1, close - open - 1));
      report("invalid JSON: " + what, at == std::string::npos ? 0 : at);
      throwIfFailed();
    }
    if (!doc.is_object())
    {
      report("the file must hold a JSON object with \"cells\"", 0);
      throwIfFailed();
    }
    Complex k;
    try
    {
      k.name = doc.value("name", std::string());
      time_ = number(doc, "time", 0.0, "the time");
      readLibrary(doc);
      readAttributes(doc, k);
      readCells(doc, k);
      readRelations(doc, k);
    }
    catch (const Json::exception& e)
    {
      // A value of another JSON type than the reading expects, where no check says so itself
      // (found by FuzzComplexJson): reported at the element being read, reading stops.
      report("a value has the wrong JSON type (" + jsonMessage(e.what()) + ")", current_);
    }
    throwIfFailed();
    return k;
  }

private:
  static std::string jsonMessage(const std::string& what)
  {
    // "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error ..." ->
    // the part after the position, which we print ourselves.
    // Other exceptions: "[json.exception.type_error.306] cannot use value() with number" -> the
    // part after the tag.
    const auto colon = what.find(": ");
    if (colon != std::string::npos)
    {
      return what.substr(colon + 2);
    }
    const auto tag = what.find("] ");
    return what.rfind("[json.exception.", 0) == 0 && tag != std::string::npos ? what.substr(tag + 2)
                                                                              : what;
  }

  void report(const std::string& message, std::size_t offset = std::string::npos)
  {
    problems_.push_back({ message, offset });
  }

  /// The offset of `"key": "value"` in the text, for locating an object by its name.
  std::size_t locate(const std::string& key, const std::string& value) const
  {
    const std::string quoted = "\"" + value + "\"";
    std::size_t at = 0;
    while ((at = text_.find(quoted, at)) != std::string::npos)
    {
      const std::size_t keyAt = text_.rfind("\"" + key + "\"", at);
      if (keyAt != std::string::npos &&
        text_.find_first_not_of(" \t\r\n:", keyAt + key.size() + 2) == at)
      {
        return at;
      }
      at += quoted.size();
    }
    return std::string::npos;
  }

  Diagnostic diagnostic(const Problem& p) const
  {
    Diagnostic d;
    d.where.file = file_;
    d.message = p.message;
    if (p.offset != std::string::npos && p.offset <= text_.size())
    {
      const std::size_t lineStart = text_.rfind('\n', p.offset == 0 ? 0 : p.offset - 1);
      const std::size_t begin = lineStart == std::string::npos || p.offset == 0 ? 0 : lineStart + 1;
      d.where.line = 1 +
        static_cast<int>(
          std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(begin), '\n'));
      d.where.column = 1 + static_cast<int>(p.offset - begin);
      const std::size_t end = text_.find('\n', begin);
      d.sourceLine =
        text_.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    }
    return d;
  }

  void throwIfFailed()
  {
    if (problems_.empty())
    {
      return;
    }
    std::vector<Diagnostic> all;
    for (const auto& p : problems_)
    {
      all.push_back(diagnostic(p));
      if (all.size() >= limits_.maxDiagnostics)
      {
        break;
      }
    }
    throw ParseError(std::move(all));
  }

  double number(const Json& j, const char* key, double fallback, const std::string& what)
  {
    if (!j.contains(key))
    {
      return fallback;
    }
    if (!j[key].is_number() || !std::isfinite(j[key].get<double>()))
    {
      report(what + " must be a finite number");
      return fallback;
    }
    return j[key].get<double>();
  }

  // --- the HyperFun library ------------------------------------------------------------------
  void readLibrary(const Json& doc)
  {
    if (doc.contains("hyperfun"))
    {
      if (!doc["hyperfun"].is_string())
      {
        report("\"hyperfun\" must be a string of HyperFun functions", locateKey("hyperfun"));
        return;
      }
      library_ = doc["hyperfun"].get<std::string>();
      libraryName_ = file_ + " (hyperfun)";
    }
    if (doc.contains("hyperfun_file"))
    {
      if (!doc["hyperfun_file"].is_string())
      {
        report("\"hyperfun_file\" must be a path", locateKey("hyperfun_file"));
        return;
      }
      const std::string path = resolve(doc["hyperfun_file"].get<std::string>());
      try
      {
        library_ += "\n" + readSourceFile(path, limits_);
      }
      catch (const ParseError& e)
      {
        report("cannot read the HyperFun library: " + e.diagnostics()[0].where.file + ": " +
            e.diagnostics()[0].message,
          locateKey("hyperfun_file"));
        return;
      }
      libraryName_ = path;
    }
  }

  std::size_t locateKey(const std::string& key) const { return text_.find("\"" + key + "\""); }

  std::string resolve(const std::string& path) const
  {
    if (!path.empty() && path[0] == '/')
    {
      return path;
    }
    const auto slash = file_.find_last_of('/');
    return slash == std::string::npos ? path : file_.substr(0, slash + 1) + path;
  }

  /// Compiles one HyperFun expression over x[dimensionality] (for mapped cells, with the array
  /// h = map(x) available), using the library's functions.
  frep::Expr compile(const std::string& expression, int coordinates, const std::string& where,
    const std::array<std::string, 3>* map = nullptr)
  {
    std::string body;
    if (map)
    {
      body = "  array h[3];\n  h[1] = " + (*map)[0] + ";\n  h[2] = " + (*map)[1] +
        ";\n  h[3] = " + (*map)[2] + ";\n";
    }
    const std::string wrapper = "\nictk_field(x[" + std::to_string(coordinates) + "], a[1])\n{\n" +
      body + "  ictk_field = " + expression + ";\n}\n";
    try
    {
      lang::HyperFunModel m =
        readHyperFun(library_ + wrapper, libraryName_.empty() ? file_ : libraryName_, "ictk_field",
          limits_, std::vector<double>{ 0.0 });
      return m.model.geometry().function();
    }
    catch (const ParseError& e)
    {
      // Errors inside the library keep their position; errors in the expression are reported
      // at the cell, with the expression quoted.
      std::string detail;
      for (const auto& d : e.diagnostics())
      {
        detail += "\n  " + d.message;
      }
      report(where + ": cannot compile '" + expression + "':" + detail, current_);
      return frep::Expr::constant(-1.0);
    }
  }

  FieldPtr field(const frep::Expr& e) { return frep::tapeField(frep::Tape::compile(e), time_); }

  std::vector<std::string> strings(const Json& cell, const char* key, const std::string& where)
  {
    std::vector<std::string> out;
    if (!cell.contains(key))
    {
      return out;
    }
    const Json& list = cell[key];
    if (!list.is_array())
    {
      report(where + ": \"" + key + "\" must be a list of HyperFun expressions", current_);
      return out;
    }
    for (const auto& item : list)
    {
      if (!item.is_string())
      {
        report(where + ": every item of \"" + key + "\" must be a string", current_);
        continue;
      }
      out.push_back(item.get<std::string>());
    }
    return out;
  }

  bool point(const Json& j, Point3& p, int size = 3)
  {
    if (!j.is_array() || static_cast<int>(j.size()) != size)
    {
      return false;
    }
    p = { 0, 0, 0 };
    for (int a = 0; a < size; ++a)
    {
      if (!j[a].is_number() || !std::isfinite(j[a].get<double>()))
      {
        return false;
      }
      p[a] = j[a].get<double>();
    }
    return true;
  }

  bool box(const Json& cell, const char* key, Box3& b, int size, const std::string& where)
  {
    if (!cell.contains(key) || !cell[key].is_array() || cell[key].size() != 2 ||
      !point(cell[key][0], b.lo, size) || !point(cell[key][1], b.hi, size))
    {
      report(where + ": \"" + key + "\" must be [[lo...], [hi...]] with " + std::to_string(size) +
          " finite numbers each",
        current_);
      return false;
    }
    for (int a = 0; a < size; ++a)
    {
      if (b.lo[a] > b.hi[a])
      {
        report(where + ": \"" + key + "\" has lo > hi on axis " + std::to_string(a), current_);
        return false;
      }
    }
    return true;
  }

  // --- attributes ----------------------------------------------------------------------------
  void readAttributes(const Json& doc, Complex& k)
  {
    if (doc.contains("attributes"))
    {
      for (const auto& item : doc["attributes"].items())
      {
        // Not a structured binding: the lambda below uses `spec`, which C++17 does not let a
        // lambda capture from a binding (clang refuses it).
        const std::string& name = item.key();
        const Json& spec = item.value();
        current_ = locateKey(name);
        complex::AttributeDefaults d;
        d.components = spec.value("components", 1);
        auto values = [&](const char* key)
        {
          std::vector<double> v;
          if (spec.contains(key) && spec[key].is_array())
          {
            for (const auto& x : spec[key])
            {
              v.push_back(x.is_number() ? x.get<double>() : NAN);
            }
          }
          return v;
        };
        d.inside = values("inside");
        d.outside = values("outside");
        try
        {
          k.declareAttribute(name, d);
        }
        catch (const std::exception& e)
        {
          report(e.what(), current_);
        }
      }
    }
    if (doc.contains("attribute_functions"))
    {
      for (const auto& [name, spec] : doc["attribute_functions"].items())
      {
        current_ = locateKey(name);
        auto f = std::make_shared<complex::AttributeFunction>();
        f->name = name;
        const Json list = spec.is_array() ? spec : Json::array({ spec });
        for (const auto& component : list)
        {
          std::string text =
            component.is_string() ? component.get<std::string>() : component.dump();
          f->text.push_back(text);
          f->components.push_back(field(compile(text, 3, "attribute function '" + name + "'")));
        }
        functions_[name] = f;
      }
    }
  }

  void bindAttributes(const Json& cell, Cell& c)
  {
    if (!cell.contains("attributes"))
    {
      return;
    }
    for (const auto& [attribute, spec] : cell["attributes"].items())
    {
      if (!spec.is_string() &&
        !(spec.is_object() && spec.contains("function") && spec["function"].is_string()))
      {
        report("cell '" + c.name + "': attribute '" + attribute +
            "' must name an attribute function: \"f\" or {\"function\": \"f\", \"priority\": p}",
          current_);
        continue;
      }
      const std::string function =
        spec.is_string() ? spec.get<std::string>() : spec["function"].get<std::string>();
      auto it = functions_.find(function);
      if (it == functions_.end())
      {
        report("cell '" + c.name + "': attribute '" + attribute +
            "' names no attribute function '" + function + "'",
          current_);
        continue;
      }
      complex::AttributeBinding b;
      b.attribute = attribute;
      b.function = it->second;
      b.priority = spec.is_object() ? spec.value("priority", 0.0) : 0.0;
      c.attributes.push_back(std::move(b));
    }
  }

  // --- cells ---------------------------------------------------------------------------------
  void readCells(const Json& doc, Complex& k)
  {
    if (!doc.contains("cells") || !doc["cells"].is_array())
    {
      report("the complex needs a list \"cells\"", 0);
      return;
    }
    for (const auto& spec : doc["cells"])
    {
      if (!spec.is_object() || !spec.contains("name") || !spec["name"].is_string())
      {
        report("every cell needs a \"name\"", 0);
        continue;
      }
      Cell c;
      c.name = spec["name"].get<std::string>();
      c.description = spec.value("description", std::string());
      current_ = locate("name", c.name);
      const std::string where = "cell '" + c.name + "'";
      c.priority = number(spec, "priority", 0.0, where + ": \"priority\"");
      try
      {
        c.kind = complex::kindFromCode(spec.value("kind", std::string("F")));
      }
      catch (const std::exception& e)
      {
        report(where + ": " + e.what(), current_);
        continue;
      }
      if (!spec.contains("dimension") || !spec["dimension"].is_number_integer())
      {
        report(where + ": \"dimension\" (0, 1, 2 or 3) is required", current_);
        continue;
      }
      c.dimension = spec["dimension"].get<int>();
      const std::size_t before = problems_.size();
      switch (c.kind)
      {
        case CellKind::Point:
        case CellKind::BRep:
          readExplicit(spec, c, where);
          break;
        case CellKind::MappedFRep:
          readMapped(spec, c, where);
          break;
        case CellKind::Composite:
        case CellKind::Computed:
          readDerived(spec, c, k, where);
          break;
        case CellKind::Voxel:
          readVoxel(spec, c, where);
          break;
        default:
          readImplicit(spec, c, where);
      }
      bindAttributes(spec, c);
      if (problems_.size() != before)
      {
        continue;
      }
      try
      {
        k.addCell(std::move(c));
      }
      catch (const std::exception& e)
      {
        report(e.what(), current_);
      }
    }
  }

  void readImplicit(const Json& spec, Cell& c, const std::string& where)
  {
    complex::ImplicitGeometry g;
    box(spec, "bounds", g.bounds, 3, where);
    g.carrierText = strings(spec, "carriers", where);
    g.insideText = strings(spec, "inside", where);
    for (const auto& t : g.carrierText)
    {
      g.carriers.push_back(field(compile(t, 3, where)));
    }
    for (const auto& t : g.insideText)
    {
      g.inside.push_back(field(compile(t, 3, where)));
    }
    c.geometry = std::move(g);
  }

  void readMapped(const Json& spec, Cell& c, const std::string& where)
  {
    complex::MappedGeometry g;
    box(spec, "uv_bounds", g.uvBounds, 2, where);
    const std::vector<std::string> map = strings(spec, "map", where);
    if (map.size() != 3)
    {
      report(where + ": \"map\" must give h(u, v) as three HyperFun expressions", current_);
      return;
    }
    std::copy(map.begin(), map.end(), g.mapText.begin());
    for (int a = 0; a < 3; ++a)
    {
      g.map[a] = field(compile(map[a], 2, where));
    }
    g.carrierText = strings(spec, "carriers", where);
    g.insideText = strings(spec, "inside", where);
    for (const auto& t : g.carrierText)
    {
      g.carriers.push_back(field(compile(t, 2, where, &g.mapText)));
    }
    for (const auto& t : g.insideText)
    {
      g.inside.push_back(field(compile(t, 2, where, &g.mapText)));
    }
    c.geometry = std::move(g);
  }

  /// A V cell: the solid where a sampled scalar field is above (or below) an iso-value, read by
  /// trilinear interpolation, optionally clipped to a box or an FRep region (docs/complex-json.md).
  void readVoxel(const Json& spec, Cell& c, const std::string& where)
  {
    if (!spec.contains("file") || !spec["file"].is_string())
    {
      report(where + ": a voxel cell needs \"file\" (.vdb, .inv3, or a VTK image through ictk)",
        current_);
      return;
    }
    if (c.dimension != 3)
    {
      report(where + ": a voxel cell is a solid; its dimension must be 3", current_);
      return;
    }
    const std::string path = resolve(spec["file"].get<std::string>());
    const std::string array = spec.value("array", std::string());
    const std::string side = spec.value("inside", std::string("above"));
    if (side != "above" && side != "below")
    {
      report(where + ": \"inside\" must be \"above\" or \"below\" the iso-value", current_);
      return;
    }
    const double iso = number(spec, "iso", 0.0, where + ": \"iso\"");
    complex::ImplicitGeometry g;
    if (spec.contains("clip") && !readClip(spec["clip"], g, where + ": \"clip\""))
    {
      return;
    }
    try
    {
      std::shared_ptr<voxel::VoxelGrid> grid;
      if (voxel::isCoreVolume(path))
      {
        grid = voxel::readCoreVolume(path, array);
      }
      else if (readers_.volume)
      {
        grid = readers_.volume(path, array);
      }
      else
      {
        throw std::invalid_argument("'" + path +
          "': only .vdb and .inv3 volumes are read without the VTK layer (use ictk or "
          "ictkComplexSource)");
      }
      voxel::validate(*grid, "'" + path + "'");
      if (spec.contains("stamp") && !readStamps(spec["stamp"], *grid, where))
      {
        return;
      }
      if (readers_.scanRead)
      {
        readers_.scanRead(c.name, grid);
      }
      const Box3 gridBox = grid->bounds();
      Box3 clipped = gridBox;
      if (!g.inside.empty())
      {
        for (int a = 0; a < 3; ++a)
        {
          clipped.lo[a] = std::max(gridBox.lo[a], g.bounds.lo[a]);
          clipped.hi[a] = std::min(gridBox.hi[a], g.bounds.hi[a]);
          if (clipped.lo[a] >= clipped.hi[a])
          {
            throw std::invalid_argument("the clip region does not meet the scan '" + path +
              "' (on axis " + std::to_string(a) + " the scan spans [" +
              std::to_string(gridBox.lo[a]) + ", " + std::to_string(gridBox.hi[a]) + "])");
          }
        }
      }
      g.bounds = clipped;
      // The scan's field first: the clip fields are the region's faces, and the CGAL backend
      // protects the curves where the iso-surface meets them (creases between inside fields).
      FieldPtr scan = voxel::voxelField(grid, iso, side == "above");
      std::string text = path + (side == "above" ? " >= " : " <= ") + std::to_string(iso);
      if (spec.contains("combine") && !readCombine(spec["combine"], scan, text, where))
      {
        return;
      }
      g.inside.insert(g.inside.begin(), scan);
      g.insideText.insert(g.insideText.begin(), text);
      c.geometry = std::move(g);
    }
    catch (const std::exception& e)
    {
      report(where + ": " + e.what(), current_);
    }
  }

  /// A voxel cell's "stamp": [{"inside": HyperFun, "value": v, "priority": p}, ...]: every grid
  /// point inside a stamp's region takes its value (voxel::stamp: an implant written into the
  /// scan with titanium's Hounsfield units, a drilled hole with air's), in ascending priority
  /// (default 0; equal priorities in list order), so the stamp of highest priority wins where
  /// regions overlap. Before the iso-surface and the combine see the grid.
  bool readStamps(const Json& list, voxel::VoxelGrid& grid, const std::string& where)
  {
    if (!list.is_array())
    {
      report(where + ": \"stamp\" must be a list of {\"inside\", \"value\"}", current_);
      return false;
    }
    struct Stamp
    {
      double priority;
      FieldPtr region;
      double value;
      std::string at;
    };
    std::vector<Stamp> stamps;
    const std::size_t before = problems_.size();
    for (std::size_t i = 0; i < list.size(); ++i)
    {
      const Json& o = list[i];
      const std::string at = where + ": stamp[" + std::to_string(i) + "]";
      if (!o.is_object() || !o.contains("inside") || !o["inside"].is_string() ||
        !o.contains("value") || !o["value"].is_number())
      {
        report(at + " must be {\"inside\": HyperFun, \"value\": number[, \"priority\": number]}",
          current_);
        return false;
      }
      const double value = o["value"].get<double>();
      if (!std::isfinite(value))
      {
        report(at + ": \"value\" must be finite", current_);
        return false;
      }
      stamps.push_back({ number(o, "priority", 0.0, at + ": \"priority\""),
        field(compile(o["inside"].get<std::string>(), 3, at)), value, at });
    }
    if (problems_.size() != before)
    {
      return false; // a region that did not compile (reported) or a bad priority
    }
    std::stable_sort(stamps.begin(), stamps.end(),
      [](const Stamp& a, const Stamp& b) { return a.priority < b.priority; });
    for (const Stamp& s : stamps)
    {
      // A region that misses every grid point is a mistake (a wrong frame or sign), not a no-op.
      if (voxel::stamp(grid, *s.region, s.value) == 0)
      {
        report(s.at + ": the region holds no point of the scan's grid", current_);
        return false;
      }
    }
    return true;
  }

  /// A voxel cell's "combine": [{"op": "union" | "intersection" | "difference" | "blend",
  /// "inside": HyperFun, ...}, ...], applied in order to the scan's field (FieldOperations.h):
  /// the R-functions with "alpha" (default 0), or the bounded blend with "bound" (HyperFun),
  /// "a0" .. "a3" (default 1).
  bool readCombine(const Json& list, FieldPtr& scan, std::string& text, const std::string& where)
  {
    if (!list.is_array())
    {
      report(where + ": \"combine\" must be a list of operations", current_);
      return false;
    }
    for (std::size_t i = 0; i < list.size(); ++i)
    {
      const Json& o = list[i];
      const std::string at = where + ": combine[" + std::to_string(i) + "]";
      const std::string op = o.is_object() ? o.value("op", std::string()) : std::string();
      if (!o.is_object() || !o.contains("inside") || !o["inside"].is_string() ||
        (op != "union" && op != "intersection" && op != "difference" && op != "blend") ||
        (op == "blend" && !(o.contains("bound") && o["bound"].is_string())))
      {
        report(at +
            " must be {\"op\": \"union\", \"intersection\", \"difference\" or \"blend\", "
            "\"inside\": HyperFun} (a blend also \"bound\": HyperFun)",
          current_);
        return false;
      }
      const std::string inside = o["inside"].get<std::string>();
      const FieldPtr shape = field(compile(inside, 3, at));
      const double alpha = number(o, "alpha", 0.0, at + ": \"alpha\"");
      if (op == "blend")
      {
        const std::string bound = o["bound"].get<std::string>();
        scan = frep::boundedBlendFields(scan, shape, field(compile(bound, 3, at)),
          number(o, "a1", 1.0, at), number(o, "a2", 1.0, at), number(o, "a3", 1.0, at),
          number(o, "a0", 1.0, at));
      }
      else
      {
        scan = op == "union"     ? frep::uniteFields(scan, shape, alpha)
          : op == "intersection" ? frep::intersectFields(scan, shape, alpha)
                                 : frep::subtractFields(scan, shape, alpha);
      }
      text = op + "(" + text + ", " + inside + ")";
    }
    return true;
  }

  /// A voxel cell's clip: {"box": [[lo], [hi]]} or {"inside": [HyperFun...], "bounds": [[lo],
  /// [hi]]}; its fields become inside fields of the cell (after the scan's) and its box bounds
  /// the cell.
  bool readClip(const Json& clip, complex::ImplicitGeometry& g, const std::string& where)
  {
    if (!clip.is_object() || (clip.contains("box") == clip.contains("inside")))
    {
      report(where +
          " must be {\"box\": [[lo], [hi]]} or {\"inside\": [HyperFun expressions], "
          "\"bounds\": [[lo], [hi]]}",
        current_);
      return false;
    }
    if (clip.contains("box"))
    {
      Box3 b;
      if (!box(clip, "box", b, 3, where))
      {
        return false;
      }
      // The box as one min of its six planes: its faces split apart again for crease tracing.
      std::ostringstream text;
      text.precision(17);
      auto slab = [&](int a)
      {
        text << "min(x[" << a + 1 << "] - (" << b.lo[a] << "), (" << b.hi[a] << ") - x[" << a + 1
             << "])";
      };
      text << "min(min(";
      slab(0);
      text << ", ";
      slab(1);
      text << "), ";
      slab(2);
      text << ")";
      g.bounds = b;
      g.insideText.push_back(text.str());
      g.inside.push_back(field(compile(text.str(), 3, where)));
      return true;
    }
    if (!box(clip, "bounds", g.bounds, 3, where))
    {
      return false;
    }
    for (const auto& t : strings(clip, "inside", where))
    {
      g.insideText.push_back(t);
      g.inside.push_back(field(compile(t, 3, where)));
    }
    return !g.inside.empty();
  }

  void readExplicit(const Json& spec, Cell& c, const std::string& where)
  {
    complex::ExplicitGeometry g;
    if (spec.contains("file"))
    {
      if (!readers_.mesh)
      {
        report(where +
            ": explicit cells from files are read by the VTK layer (ictk, "
            "ictkComplexSource)",
          current_);
        return;
      }
      try
      {
        c.geometry = readers_.mesh(resolve(spec.value("file", std::string())));
      }
      catch (const std::exception& e)
      {
        report(where + ": " + e.what(), current_);
      }
      return;
    }
    if (spec.contains("curve"))
    {
      readCurve(spec["curve"], g, where);
    }
    else if (spec.contains("points") && spec["points"].is_array())
    {
      for (const auto& p : spec["points"])
      {
        Point3 q;
        if (!point(p, q))
        {
          report(where + ": every point must be [x, y, z] with finite numbers", current_);
          return;
        }
        g.points.push_back(q);
      }
    }
    auto indices = [&](const char* key, auto& out)
    {
      if (!spec.contains(key))
      {
        return;
      }
      for (const auto& item : spec[key])
      {
        typename std::decay_t<decltype(out)>::value_type element{};
        if (!item.is_array())
        {
          report(where + ": \"" + key + "\" must be a list of index lists", current_);
          return;
        }
        std::vector<std::uint32_t> list;
        for (const auto& i : item)
        {
          if (!i.is_number_unsigned())
          {
            report(where + ": indices in \"" + key + "\" must be non-negative integers", current_);
            return;
          }
          list.push_back(i.get<std::uint32_t>());
        }
        if constexpr (std::is_same_v<decltype(element), std::vector<std::uint32_t>>)
        {
          element = list;
        }
        else
        {
          if (list.size() != element.size())
          {
            report(where + ": every item of \"" + key + "\" needs " +
                std::to_string(element.size()) + " indices",
              current_);
            return;
          }
          std::copy(list.begin(), list.end(), element.begin());
        }
        out.push_back(element);
      }
    };
    indices("polylines", g.polylines);
    indices("triangles", g.triangles);
    indices("tetrahedra", g.tetrahedra);
    c.geometry = std::move(g);
  }

  /// A Bezier curve of any degree, sampled by de Casteljau's algorithm.
  void readCurve(const Json& curve, complex::ExplicitGeometry& g, const std::string& where)
  {
    std::vector<Point3> control;
    if (curve.contains("bezier") && curve["bezier"].is_array())
    {
      for (const auto& p : curve["bezier"])
      {
        Point3 q;
        if (!point(p, q))
        {
          report(where + ": Bezier control points must be [x, y, z]", current_);
          return;
        }
        control.push_back(q);
      }
    }
    if (control.size() < 2)
    {
      report(where + ": \"curve\" needs \"bezier\" with at least two control points", current_);
      return;
    }
    const int samples = curve.value("samples", 64);
    if (samples < 1 || samples > 1000000)
    {
      report(where + ": \"samples\" must be between 1 and 1000000", current_);
      return;
    }
    std::vector<std::uint32_t> line;
    for (int i = 0; i <= samples; ++i)
    {
      const double t = double(i) / samples;
      std::vector<Point3> work = control;
      for (std::size_t level = work.size() - 1; level > 0; --level)
      {
        for (std::size_t j = 0; j < level; ++j)
        {
          for (int a = 0; a < 3; ++a)
          {
            work[j][a] = (1 - t) * work[j][a] + t * work[j + 1][a];
          }
        }
      }
      line.push_back(static_cast<std::uint32_t>(g.points.size()));
      g.points.push_back(work[0]);
    }
    g.polylines.push_back(std::move(line));
  }

  /// C cells (a set operation on 3D cells) and T cells (the boundaries of some cells, trimmed by
  /// the insides of others).
  void readDerived(const Json& spec, Cell& c, const Complex& k, const std::string& where)
  {
    auto solids = [&](const char* key)
    {
      std::vector<const Cell*> out;
      if (!spec.contains(key))
      {
        return out;
      }
      for (const auto& name : spec[key])
      {
        const Cell* operand = name.is_string() ? k.findCell(name.get<std::string>()) : nullptr;
        const auto* g =
          operand ? std::get_if<complex::ImplicitGeometry>(&operand->geometry) : nullptr;
        if (!g || operand->dimension != 3)
        {
          report(where + ": \"" + key + "\" must name 3D implicit cells defined earlier (" +
              name.dump() + " is not one)",
            current_);
          continue;
        }
        c.operands.push_back(operand->id);
        out.push_back(operand);
      }
      return out;
    };
    auto solidField = [](const Cell* cell)
    {
      const auto& g = std::get<complex::ImplicitGeometry>(cell->geometry);
      return g.inside.size() == 1 ? g.inside[0] : frep::minField(g.inside);
    };
    complex::ImplicitGeometry g;
    const double inf = std::numeric_limits<double>::infinity();
    g.bounds = { { -inf, -inf, -inf }, { inf, inf, inf } };
    auto clip = [&](const Cell* cell)
    {
      const Box3 b = cell->bounds();
      for (int a = 0; a < 3; ++a)
      {
        g.bounds.lo[a] = std::max(g.bounds.lo[a], b.lo[a]);
        g.bounds.hi[a] = std::min(g.bounds.hi[a], b.hi[a]);
      }
    };
    if (c.kind == CellKind::Composite)
    {
      const std::string op = spec.value("operation", std::string());
      const auto operands = solids("operands");
      if (operands.size() < 2)
      {
        report(where + ": a composite cell needs \"operands\" naming two or more cells", current_);
        return;
      }
      if (op == "union")
      {
        std::vector<FieldPtr> fields;
        g.bounds = operands[0]->bounds();
        for (const Cell* o : operands)
        {
          fields.push_back(solidField(o));
          const Box3 b = o->bounds();
          for (int a = 0; a < 3; ++a)
          {
            g.bounds.lo[a] = std::min(g.bounds.lo[a], b.lo[a]);
            g.bounds.hi[a] = std::max(g.bounds.hi[a], b.hi[a]);
          }
        }
        g.inside.push_back(frep::maxField(fields));
      }
      else if (op == "intersection" || op == "difference")
      {
        for (std::size_t i = 0; i < operands.size(); ++i)
        {
          const FieldPtr f = solidField(operands[i]);
          const bool subtract = op == "difference" && i > 0;
          g.inside.push_back(subtract ? frep::negatedField(f) : f);
          if (!subtract)
          {
            clip(operands[i]);
          }
        }
      }
      else
      {
        report(where + ": \"operation\" must be union, intersection or difference", current_);
        return;
      }
    }
    else
    {
      for (const Cell* o : solids("boundary_of"))
      {
        g.carriers.push_back(solidField(o));
        clip(o);
      }
      for (const Cell* o : solids("inside_of"))
      {
        g.inside.push_back(solidField(o));
        clip(o);
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      if (!(g.bounds.lo[a] <= g.bounds.hi[a]))
      {
        report(where + ": its operands do not overlap, so the cell is empty", current_);
        return;
      }
    }
    c.geometry = std::move(g);
  }

  // --- relations -----------------------------------------------------------------------------
  void readRelations(const Json& doc, Complex& k)
  {
    if (!doc.contains("relations"))
    {
      return;
    }
    for (const char* kind : { "boundary", "containment" })
    {
      if (!doc["relations"].contains(kind))
      {
        continue;
      }
      for (const auto& pair : doc["relations"][kind])
      {
        if (!pair.is_array() || pair.size() != 2 || !pair[0].is_string() || !pair[1].is_string())
        {
          report(std::string("relations.") + kind + ": every pair must be [\"cell\", \"cell\"]",
            locateKey(kind));
          continue;
        }
        const std::string a = pair[0].get<std::string>();
        const std::string b = pair[1].get<std::string>();
        const std::size_t at = text_.find("\"" + a + "\", \"" + b + "\"");
        try
        {
          if (std::string(kind) == "boundary")
          {
            k.addBoundary(k.idOf(a), k.idOf(b));
          }
          else
          {
            k.addContainment(k.idOf(a), k.idOf(b));
          }
        }
        catch (const std::exception& e)
        {
          report(std::string(kind) + " relation (" + a + ", " + b + "): " + e.what(),
            at == std::string::npos ? locateKey(kind) : at);
        }
      }
    }
  }

  const std::string& text_;
  std::string file_;
  Limits limits_;
  ComplexFileReaders readers_;
  double time_ = 0;
  std::string library_;
  std::string libraryName_;
  std::map<std::string, complex::AttributeFunctionPtr> functions_;
  std::vector<Problem> problems_;
  std::size_t current_ = std::string::npos;
};

} // namespace

bool isComplexFile(const std::string& path)
{
  if (path.size() < 5)
  {
    return false;
  }
  std::string ext = path.substr(path.size() - 5);
  std::transform(ext.begin(), ext.end(), ext.begin(),
    [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext == ".json";
}

complex::Complex readComplexJson(const std::string& text, const std::string& fileName,
  const Limits& limits, const ComplexFileReaders& readers)
{
  if (text.size() > limits.maxFileBytes)
  {
    Diagnostic d;
    d.where.file = fileName;
    d.message =
      "the file is larger than the limit of " + std::to_string(limits.maxFileBytes) + " bytes";
    throw ParseError({ d });
  }
  return Reader(text, fileName, limits, readers).read();
}

complex::Complex readComplexFile(
  const std::string& path, const Limits& limits, const ComplexFileReaders& readers)
{
  return readComplexJson(readSourceFile(path, limits), path, limits, readers);
}

} // namespace ictk::lang
