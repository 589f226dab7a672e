// SPDX-License-Identifier: BSD-3-Clause
#include "Voxel/VdbIO.h"
#include "Voxel/VdbDetail.h"

#include "FRep/Sampling.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace ictk::voxel
{
namespace
{

namespace fs = std::filesystem;

std::string inQuotes(const std::string& s)
{
  return "'" + s + "'";
}

/// The grid names and value types of an open file, in the order of its index.
std::vector<std::pair<std::string, std::string>> gridsOf(openvdb::io::File& file)
{
  std::vector<std::pair<std::string, std::string>> grids;
  openvdb::GridPtrVecPtr all = file.readAllGridMetadata();
  for (const auto& g : *all)
  {
    grids.emplace_back(g->getName(), g->valueType());
  }
  return grids;
}

std::string describe(const std::vector<std::pair<std::string, std::string>>& grids)
{
  if (grids.empty())
  {
    return "the file holds no grids";
  }
  std::string s = "the file holds";
  for (std::size_t i = 0; i < grids.size(); ++i)
  {
    s += (i ? ", " : " ") + inQuotes(grids[i].first) + " (" + grids[i].second + ")";
  }
  return s;
}

template <typename GridT>
void densify(const GridT& grid, const openvdb::CoordBBox& box, VoxelGrid& out)
{
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, out.values.data());
  openvdb::tools::copyToDense(grid, dense);
}

} // namespace

std::shared_ptr<VoxelGrid> readVdb(
  const std::string& path, const std::string& gridName, std::int64_t maxVoxels)
{
  const std::string where = "readVdb: " + inQuotes(path);
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status))
  {
    throw std::runtime_error(where + ": no such file");
  }
  if (fs::is_directory(status))
  {
    throw std::runtime_error(where + ": is a folder, not an OpenVDB file");
  }
  detail::initialiseOpenVdb();

  openvdb::io::File file(path);
  std::vector<std::pair<std::string, std::string>> grids;
  try
  {
    // Read everything now (no delayed loading): the file may be replaced after this call.
    file.open(false);
    grids = gridsOf(file);
  }
  catch (const openvdb::Exception& e)
  {
    throw std::runtime_error(where + ": not a readable OpenVDB file (" + e.what() + ")");
  }

  std::string name = gridName;
  std::string type;
  if (name.empty())
  {
    for (const char* wanted : { "float", "double" })
    {
      for (const auto& g : grids)
      {
        if (type.empty() && g.second == wanted)
        {
          name = g.first;
          type = g.second;
        }
      }
    }
    if (type.empty())
    {
      throw std::runtime_error(where + ": no float or double grid; " + describe(grids));
    }
  }
  else
  {
    for (const auto& g : grids)
    {
      if (type.empty() && g.first == name)
      {
        type = g.second;
      }
    }
    if (type.empty())
    {
      throw std::runtime_error(
        where + ": no grid named " + inQuotes(name) + "; " + describe(grids));
    }
    if (type != "float" && type != "double")
    {
      throw std::runtime_error(where + ": grid " + inQuotes(name) + " holds " + type +
        " values; only float and double grids can be read");
    }
  }
  const std::string what = where + ", grid " + inQuotes(name);

  openvdb::GridBase::Ptr base;
  try
  {
    base = file.readGrid(name);
    file.close();
  }
  catch (const openvdb::Exception& e)
  {
    throw std::runtime_error(what + ": cannot be read (" + e.what() + ")");
  }

  // Transform: index -> world must be x * scale + translation with a diagonal positive scale.
  const openvdb::math::Transform& xf = base->transform();
  if (!xf.isLinear())
  {
    throw std::runtime_error(what + ": its transform (" + xf.mapType() +
      ") is not linear; only scale + translation is supported");
  }
  const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
  Point3 scale{ m(0, 0), m(1, 1), m(2, 2) };
  const double size = std::max({ std::abs(scale[0]), std::abs(scale[1]), std::abs(scale[2]) });
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      if (r != c && !(std::abs(m(r, c)) <= 1e-12 * size))
      {
        throw std::runtime_error(what + ": its transform (" + xf.mapType() +
          ") rotates or shears; only an axis-aligned scale + translation is supported");
      }
    }
    if (!(scale[r] > 0) || !std::isfinite(scale[r]))
    {
      std::ostringstream os;
      os << what << ": its transform scales axis " << r << " by " << scale[r]
         << "; only a positive (axis-aligned) scale + translation is supported";
      throw std::runtime_error(os.str());
    }
  }
  const openvdb::Vec3d translation = m.getTranslation();

  openvdb::CoordBBox box = base->evalActiveVoxelBoundingBox();
  if (box.empty())
  {
    throw std::runtime_error(what + ": the grid has no active voxels");
  }
  box.expand(1);
  std::array<std::int64_t, 3> dims;
  long double count = 1;
  for (int a = 0; a < 3; ++a)
  {
    dims[a] = static_cast<std::int64_t>(box.max()[a]) - static_cast<std::int64_t>(box.min()[a]) + 1;
    count *= static_cast<long double>(dims[a]);
  }
  if (count > static_cast<long double>(maxVoxels))
  {
    std::ostringstream os;
    os << what << ": densifying it needs " << dims[0] << " x " << dims[1] << " x " << dims[2]
       << " = " << static_cast<double>(count)
       << " voxels (active bounding box plus a one-voxel margin), above the budget of " << maxVoxels
       << " voxels";
    throw std::runtime_error(os.str());
  }
  frep::Grid check;
  check.dimensions = dims;
  try
  {
    frep::checkGrid(check, sizeof(float));
  }
  catch (const std::invalid_argument& e)
  {
    throw std::runtime_error(what + ": " + e.what());
  }

  auto out = std::make_shared<VoxelGrid>();
  out->dimensions = dims;
  for (int a = 0; a < 3; ++a)
  {
    out->spacing[a] = scale[a];
    out->origin[a] = static_cast<double>(box.min()[a]) * scale[a] + translation[a];
  }
  out->values.resize(static_cast<std::size_t>(out->pointCount()));
  try
  {
    if (auto fg = openvdb::gridPtrCast<openvdb::FloatGrid>(base))
    {
      densify(*fg, box, *out);
    }
    else if (auto dg = openvdb::gridPtrCast<openvdb::DoubleGrid>(base))
    {
      densify(*dg, box, *out);
    }
    else
    {
      throw std::runtime_error(what + ": holds " + base->valueType() + " values");
    }
  }
  catch (const openvdb::Exception& e)
  {
    throw std::runtime_error(what + ": cannot be densified (" + e.what() + ")");
  }
  validate(*out, what);
  return out;
}

void writeVdb(const VoxelGrid& grid, const std::string& path, const std::string& gridName,
  std::optional<float> background)
{
  const std::string where = "writeVdb: " + inQuotes(path);
  validate(grid, where);
  if (gridName.empty())
  {
    throw std::invalid_argument(where + ": the grid name is empty");
  }
  const float bg = background ? *background : grid.values[0];
  if (!std::isfinite(bg))
  {
    throw std::invalid_argument(where + ": the background value must be finite");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (grid.dimensions[a] > std::int64_t(1) << 30)
    {
      throw std::invalid_argument(where + ": too many points along an axis for OpenVDB");
    }
  }
  detail::initialiseOpenVdb();

  openvdb::FloatGrid::Ptr vdb = openvdb::FloatGrid::create(bg);
  vdb->setName(gridName);
  vdb->setTransform(detail::gridTransform(grid.origin, grid.spacing));
  const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0),
    openvdb::Coord(static_cast<openvdb::Int32>(grid.dimensions[0] - 1),
      static_cast<openvdb::Int32>(grid.dimensions[1] - 1),
      static_cast<openvdb::Int32>(grid.dimensions[2] - 1)));
  // copyFromDense only reads the array. A negative tolerance keeps every voxel active.
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(
    box, const_cast<float*>(grid.values.data()));
  openvdb::tools::copyFromDense(dense, *vdb, -1.0f);

  detail::writeAtomically(vdb, path, where);
}

namespace detail
{

void initialiseOpenVdb()
{
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr gridTransform(
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing)
{
  const openvdb::Vec3d o(origin[0], origin[1], origin[2]);
  if (spacing[0] == spacing[1] && spacing[1] == spacing[2])
  {
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(spacing[0]);
    xf->postTranslate(o);
    return xf;
  }
  const openvdb::Vec3d s(spacing[0], spacing[1], spacing[2]);
  return std::make_shared<openvdb::math::Transform>(
    std::make_shared<openvdb::math::ScaleTranslateMap>(s, o));
}

void writeAtomically(
  const openvdb::GridBase::Ptr& vdb, const std::string& path, const std::string& where)
{
  // Write next to the target, then rename over it (atomic on one file system).
  static std::atomic<unsigned> counter{ 0 };
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
  {
    throw std::runtime_error(
      where + ": the folder " + inQuotes(folder.string()) + " does not exist");
  }
  const fs::path temporary = folder /
    ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
      std::to_string(counter++));
  try
  {
    openvdb::io::File file(temporary.string());
    openvdb::GridPtrVec grids{ vdb };
    file.write(grids);
    file.close();
    if (fs::file_size(temporary) == 0)
    {
      throw std::runtime_error("the written file is empty");
    }
    fs::rename(temporary, target);
  }
  catch (const std::exception& e)
  {
    fs::remove(temporary, ec);
    throw std::runtime_error(where + ": cannot write the file (" + e.what() + ")");
  }
}

} // namespace detail

} // namespace ictk::voxel
