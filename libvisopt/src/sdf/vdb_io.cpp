// OpenVDB file IO for SDFs and the dense resampling shared with the mesh conversion.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>

#include <openvdb/io/File.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include "core/field_view.h"
#include "io/file_util.h"
#include "sdf/mesh_loading.h"
#include "sdf/sdf_resample.h"
#include "visopt/error.h"
#include "visopt/sdf.h"
#include "visopt/volume_io.h"

namespace visopt {
namespace sdf {

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr linearTransform(const GridSpec& grid, glm::dvec3 scale) {
  // OpenVDB maps row vectors: world = (i, j, k, 1) * M, so row r is the world step of axis r.
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = double(grid.direction[r][c]) * scale[r];
  for (int c = 0; c < 3; ++c) m[3][c] = double(grid.origin[c]);
  return openvdb::math::Transform::createLinearTransform(m);
}

void resampleToDense(const openvdb::FloatGrid& vdb, Field3D& out, bool absolute, float offset,
                     const ProgressCallback& progress, const std::string& path, float from,
                     float to, const std::string& stage) {
  const GridSpec& g = out.grid();
  const openvdb::math::Transform& xform = vdb.transform();
  // Both maps are affine, so dense index -> VDB index is affine too: base + A * (i, j, k).
  auto vdbIndexOf = [&](glm::dvec3 ijk) {
    const glm::dvec3 world =
        glm::dvec3(g.origin) + glm::dmat3(g.direction) * (ijk * glm::dvec3(g.spacing));
    return xform.worldToIndex(openvdb::Vec3d(world.x, world.y, world.z));
  };
  const openvdb::Vec3d base = vdbIndexOf(glm::dvec3(0.0));
  const openvdb::Vec3d axis[3] = {vdbIndexOf(glm::dvec3(1, 0, 0)) - base,
                                  vdbIndexOf(glm::dvec3(0, 1, 0)) - base,
                                  vdbIndexOf(glm::dvec3(0, 0, 1)) - base};
  FieldView view(out);
  const int slabs = std::max(1, std::min(g.dims.z, 20));
  for (int s = 0; s < slabs; ++s) {
    const int k0 = int(int64_t(g.dims.z) * s / slabs),
              k1 = int(int64_t(g.dims.z) * (s + 1) / slabs);
    tbb::parallel_for(
        tbb::blocked_range2d<int>(k0, k1, 0, g.dims.y), [&](const tbb::blocked_range2d<int>& r) {
          auto accessor = vdb.getConstAccessor();
          for (int k = r.rows().begin(); k < r.rows().end(); ++k)
            for (int j = r.cols().begin(); j < r.cols().end(); ++j) {
              const openvdb::Vec3d row = base + axis[1] * double(j) + axis[2] * double(k);
              for (int i = 0; i < g.dims.x; ++i) {
                float v = openvdb::tools::BoxSampler::sample(accessor, row + axis[0] * double(i));
                if (absolute) v = std::fabs(v);
                view.store(g.linearIndex(i, j, k), v - offset);
              }
            }
        });
    reportProgress(progress, path, from + (to - from) * float(s + 1) / float(slabs), stage);
  }
}

namespace {

// The dense grid of the active voxels' bounding box in the VDB's own index space.
GridSpec gridOfActiveBox(const openvdb::FloatGrid& vdb, const std::string& path) {
  const openvdb::math::Transform& xform = vdb.transform();
  if (!xform.isLinear()) throwBadInput(path, "the grid's transform is not linear (a frustum?)");
  const openvdb::CoordBBox box = vdb.evalActiveVoxelBoundingBox();
  if (box.empty()) throwBadInput(path, "the grid has no active voxels");
  const openvdb::Coord dim = box.dim();
  GridSpec g;
  g.dims = glm::ivec3(dim.x(), dim.y(), dim.z());
  const openvdb::math::Mat4d m = xform.baseMap()->getAffineMap()->getMat4();
  for (int r = 0; r < 3; ++r) {
    const glm::dvec3 step(m[r][0], m[r][1], m[r][2]);
    const double length = glm::length(step);
    if (!(length > 0.0)) throwBadInput(path, "the grid's transform is degenerate");
    g.spacing[r] = float(length);
    g.direction[r] = glm::vec3(step / length);
  }
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      if (std::fabs(glm::dot(g.direction[a], g.direction[b])) > 1e-4f)
        throwBadInput(path, "the grid's transform is sheared, which a dense grid cannot hold");
  const openvdb::Vec3d origin = xform.indexToWorld(box.min());
  g.origin = glm::vec3(float(origin.x()), float(origin.y()), float(origin.z()));
  return g;
}

bool gridIsSet(const GridSpec& g) {
  return g.dims.x > 0 && g.dims.y > 0 && g.dims.z > 0;
}

}  // namespace
}  // namespace sdf

Field3D readSdfVdb(const std::string& path, const GridSpec& like, Precision precision,
                   MemoryLedger* ledger) {
  io::checkedFileSize(path);
  sdf::initializeOpenVdb();
  openvdb::FloatGrid::Ptr vdb;
  try {
    openvdb::io::File file(path);
    file.open(false);
    for (auto name = file.beginName(); name != file.endName() && !vdb; ++name) {
      openvdb::GridBase::Ptr base = file.readGrid(name.gridName());
      vdb = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    }
    file.close();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    what = what.substr(0, what.find('\n'));
    throwBadInput(path, "not a readable OpenVDB file (" + what + ")");
  } catch (...) {
    throwBadInput(path, "not a readable OpenVDB file");
  }
  if (!vdb) throwBadInput(path, "the file holds no float grid");

  GridSpec grid = sdf::gridIsSet(like) ? like : sdf::gridOfActiveBox(*vdb, path);
  if (!vdb->transform().isLinear())
    throwBadInput(path, "the grid's transform is not linear (a frustum?)");
  const size_t bytes = grid.voxelCount() * bytesPerValue(precision);
  if (bytes > availableMemoryBytes())
    throwBadInput(path, "a dense grid of " + std::to_string(grid.dims.x) + "x" +
                            std::to_string(grid.dims.y) + "x" + std::to_string(grid.dims.z) +
                            " voxels does not fit in the available memory");
  Field3D out("sdf", grid, precision, ledger);
  sdf::resampleToDense(*vdb, out, false, 0.f, {}, path, 0.f, 1.f, "resample");
  return out;
}

void writeSdfVdb(const Field3D& sdf, const std::string& path, float bandVoxels) {
  if (sdf.empty()) throw Error(ErrorKind::Usage, path + ": no SDF to write");
  if (!(bandVoxels >= 1.f))
    throw Error(ErrorKind::Usage, path + ": the narrow band must be >= 1 voxel");
  sdf::initializeOpenVdb();
  const GridSpec& g = sdf.grid();
  const float maxSpacing = std::max(g.spacing.x, std::max(g.spacing.y, g.spacing.z));
  float background = bandVoxels * maxSpacing;
  auto vdb = openvdb::FloatGrid::create(background);
  vdb->setTransform(sdf::linearTransform(g, glm::dvec3(g.spacing)));
  auto copyBand = [&](float limit) {
    auto accessor = vdb->getAccessor();
    size_t copied = 0;
    for (int k = 0; k < g.dims.z; ++k)
      for (int j = 0; j < g.dims.y; ++j)
        for (int i = 0; i < g.dims.x; ++i) {
          const float v = sdf.get(g.linearIndex(i, j, k));
          if (std::isfinite(v) && std::fabs(v) < limit) {
            accessor.setValue(openvdb::Coord(i, j, k), v);
            ++copied;
          }
        }
    return copied;
  };
  if (copyBand(background) == 0) {
    // No surface inside the grid: keep every voxel so the file still describes the region.
    float largest = 0.f;
    for (size_t i = 0; i < sdf.size(); ++i)
      if (std::isfinite(sdf.get(i))) largest = std::max(largest, std::fabs(sdf.get(i)));
    background = std::nextafter(largest, INFINITY) + maxSpacing;
    vdb = openvdb::FloatGrid::create(background);
    vdb->setTransform(sdf::linearTransform(g, glm::dvec3(g.spacing)));
    copyBand(background);
  }
  openvdb::tools::signedFloodFill(vdb->tree());
  vdb->setGridClass(openvdb::GRID_LEVEL_SET);
  vdb->setName("sdf");

  const std::string temporary = io::makeTemporarySibling(path, ".vdb");
  try {
    openvdb::io::File file(temporary);
    file.write({vdb});
    file.close();
  } catch (const std::exception& e) {
    io::discardTemporary(temporary);
    std::string what = e.what();
    throw Error(ErrorKind::Failure, path + ": cannot write: " + what.substr(0, what.find('\n')));
  }
  io::commitTemporary(temporary, path);
}

}  // namespace visopt
