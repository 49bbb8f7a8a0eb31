// Mesh -> dense SDF. OpenVDB's meshToVolume computes the exact (signed or unsigned) distance and
// the closest triangle in a narrow band on cubic voxels laid out in the dense grid's frame;
// closest-triangle propagation extends the exact point-triangle distance to the whole grid (a
// band of OpenVDB's own covering the grid cost ~10x more), and trilinear resampling carries it
// onto the dense grid's (possibly anisotropic) voxels.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/util/NullInterrupter.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/field_view.h"
#include "sdf/mesh_loading.h"
#include "sdf/sdf_resample.h"
#include "visopt/error.h"
#include "visopt/sdf.h"
#include "visopt/volume_io.h"

namespace visopt {
namespace {

// Forwards OpenVDB's interrupt polls to the progress callback. Polls come from worker threads
// too: one at a time (the others skip), at most every 50 ms.
class ProgressInterrupter : public openvdb::util::NullInterrupter {
 public:
  ProgressInterrupter(const ProgressCallback& progress, float fraction, std::string stage)
      : progress_(progress), fraction_(fraction), stage_(std::move(stage)) {}

  bool wasInterrupted(int /*percent*/ = -1) override {
    if (cancelled_.load(std::memory_order_relaxed)) return true;
    if (!progress_) return false;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return false;
    const auto now = std::chrono::steady_clock::now();
    if (polled_ && now - last_ < std::chrono::milliseconds(50)) return false;
    polled_ = true;
    last_ = now;
    if (!progress_(fraction_, stage_)) cancelled_.store(true);
    return cancelled_.load();
  }
  bool cancelled() const { return cancelled_.load(); }

 private:
  const ProgressCallback& progress_;
  float fraction_;
  std::string stage_;
  std::mutex mutex_;
  bool polled_ = false;
  std::chrono::steady_clock::time_point last_;
  std::atomic<bool> cancelled_{false};
};

bool gridIsSet(const GridSpec& g) {
  return g.dims.x > 0 && g.dims.y > 0 && g.dims.z > 0;
}

// Cubic voxels of `voxel` around [lo, hi] with `padding` voxels on every side, centred.
GridSpec gridAround(const std::string& path, glm::vec3 lo, glm::vec3 hi, float voxel, int padding) {
  GridSpec g;
  for (int c = 0; c < 3; ++c) {
    const double n = std::ceil(double(hi[c] - lo[c]) / double(voxel)) + 1.0 + 2.0 * padding;
    if (!(n <= 100000.0))
      throw Error(ErrorKind::Usage, path + ": the voxel size is too small for the mesh");
    g.dims[c] = int(n);
  }
  g.spacing = glm::vec3(voxel);
  g.origin = 0.5f * (lo + hi) - 0.5f * glm::vec3(g.dims - 1) * voxel;
  return g;
}

// Distance from p to the triangle (a, b, c): the closest point is a vertex, a point on an edge
// or inside the face, told apart by the barycentric regions of p's projection.
float pointTriangleDistance(glm::vec3 p, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.f && d2 <= 0.f) return glm::length(ap);
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.f && d4 <= d3) return glm::length(bp);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) return glm::length(ap - ab * (d1 / (d1 - d3)));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.f && d5 <= d6) return glm::length(cp);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) return glm::length(ap - ac * (d2 / (d2 - d6)));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && d4 - d3 >= 0.f && d5 - d6 >= 0.f)
    return glm::length(bp - (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const float denom = 1.f / (va + vb + vc);
  return glm::length(ap - ab * (vb * denom) - ac * (vc * denom));
}

// The distance on a dense grid of cubic voxels ("work grid", voxel = one VDB index step, index
// (0,0,0) at the dense grid's origin) covering the dense grid. OpenVDB gives the exact distance
// and the closest triangle in a narrow band, plus the inside/outside sign everywhere (a level
// set's inactive values carry it); beyond the band every voxel takes the closest triangle of
// its neighbours (closest-point propagation, row passes along each axis, both directions,
// twice) and its exact distance to that triangle.
class WorkGrid {
 public:
  WorkGrid(glm::ivec3 dims, const std::vector<glm::vec3>& points,
           const std::vector<glm::uvec3>& triangles)
      : dims_(dims),
        points_(points),
        triangles_(triangles),
        id_(size(), -1),
        distance_(size(), std::numeric_limits<float>::max()) {}

  size_t size() const { return size_t(dims_.x) * size_t(dims_.y) * size_t(dims_.z); }
  size_t index(int i, int j, int k) const {
    return (size_t(k) * size_t(dims_.y) + size_t(j)) * size_t(dims_.x) + size_t(i);
  }
  bool contains(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < dims_.x && j < dims_.y && k < dims_.z;
  }

  void seed(int i, int j, int k, int32_t triangle) {
    offer(index(i, j, k), glm::vec3(i, j, k), triangle);
  }
  bool seeded() const {
    return std::any_of(id_.begin(), id_.end(), [](int32_t t) { return t >= 0; });
  }
  // Brute force for one voxel (when the narrow band misses the grid entirely).
  void seedNearest(int i, int j, int k) {
    for (size_t t = 0; t < triangles_.size(); ++t) seed(i, j, k, int32_t(t));
  }

  // One pass along `axis` in both directions, rows in parallel.
  void propagate(int axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    const int n = dims_[axis];
    tbb::parallel_for(tbb::blocked_range<int>(0, dims_[a1] * dims_[a2]),
                      [&](const tbb::blocked_range<int>& rows) {
                        for (int row = rows.begin(); row < rows.end(); ++row) {
                          glm::ivec3 c(0);
                          c[a1] = row % dims_[a1];
                          c[a2] = row / dims_[a1];
                          auto at = [&](int s) {
                            c[axis] = s;
                            return std::make_pair(index(c.x, c.y, c.z), glm::vec3(c));
                          };
                          for (int s = 1; s < n; ++s) {
                            const int32_t from = id_[at(s - 1).first];
                            const auto [here, p] = at(s);
                            offer(here, p, from);
                          }
                          for (int s = n - 2; s >= 0; --s) {
                            const int32_t from = id_[at(s + 1).first];
                            const auto [here, p] = at(s);
                            offer(here, p, from);
                          }
                        }
                      });
  }

  float distance(size_t i) const { return distance_[i]; }

 private:
  void offer(size_t i, glm::vec3 p, int32_t triangle) {
    if (triangle < 0 || triangle == id_[i]) return;
    const glm::uvec3& t = triangles_[size_t(triangle)];
    const float d = pointTriangleDistance(p, points_[t.x], points_[t.y], points_[t.z]);
    if (d < distance_[i]) {
      distance_[i] = d;
      id_[i] = triangle;
    }
  }

  glm::ivec3 dims_;
  const std::vector<glm::vec3>& points_;
  const std::vector<glm::uvec3>& triangles_;
  std::vector<int32_t> id_;
  std::vector<float> distance_;
};

}  // namespace

Field3D sdfFromMesh(const std::string& path, const MeshSdfOptions& options, Precision precision,
                    MemoryLedger* ledger, MeshReport* report, const ProgressCallback& progress) {
  if (!options.filled && !(options.shellThickness > 0.f && std::isfinite(options.shellThickness)))
    throw Error(ErrorKind::Usage, path + ": a thin shell needs a thickness > 0");
  const bool like = gridIsSet(options.like);
  if (!like && !(options.voxelSize > 0.f && std::isfinite(options.voxelSize)))
    throw Error(ErrorKind::Usage, path + ": give a grid to sample on or a voxel size > 0");
  if (!like && options.paddingVoxels < 0)
    throw Error(ErrorKind::Usage, path + ": the padding must be >= 0 voxels");

  MeshReport localReport;
  MeshReport& rep = report ? *report : localReport;
  sdf::TriangleMesh mesh = sdf::loadMesh(path, rep, progress, 0.2f);
  const std::string hint =
      ": a filled SDF needs a closed manifold surface; use a thin shell "
      "(--shell D)";
  if (options.filled && !rep.closed)
    throwBadInput(
        path, "the mesh is open (" + std::to_string(rep.boundaryEdges) + " boundary edges)" + hint);
  if (options.filled && !rep.manifold)
    throwBadInput(path, "the mesh is non-manifold (" + std::to_string(rep.nonManifoldEdges) +
                            " edges shared by more than two faces)" + hint);

  const glm::vec3 lo(rep.bboxMin[0], rep.bboxMin[1], rep.bboxMin[2]);
  const glm::vec3 hi(rep.bboxMax[0], rep.bboxMax[1], rep.bboxMax[2]);
  const GridSpec grid =
      like ? options.like : gridAround(path, lo, hi, options.voxelSize, options.paddingVoxels);
  if (grid.voxelCount() * bytesPerValue(precision) > availableMemoryBytes())
    throw Error(ErrorKind::Usage, path + ": a grid of " + std::to_string(grid.dims.x) + "x" +
                                      std::to_string(grid.dims.y) + "x" +
                                      std::to_string(grid.dims.z) +
                                      " voxels does not fit in the available memory");

  // The work grid: cubic voxels of the smallest spacing, axes along the dense grid's, index
  // space shared with the sparse OpenVDB grid.
  sdf::initializeOpenVdb();
  const double voxel = double(grid.minSpacing());
  const glm::dvec3 extent = glm::dvec3(grid.dims - 1) * glm::dvec3(grid.spacing) / voxel;
  const glm::ivec3 workDims = glm::ivec3(glm::ceil(extent - 1e-3)) + 1;
  openvdb::math::Transform::Ptr xform = sdf::linearTransform(grid, glm::dvec3(voxel));
  std::vector<glm::vec3> points(mesh.points.size());
  const glm::dmat3 toLocal = glm::transpose(glm::dmat3(grid.direction));
  for (size_t i = 0; i < points.size(); ++i)
    points[i] = glm::vec3(toLocal * (glm::dvec3(mesh.points[i]) - glm::dvec3(grid.origin)) / voxel);
  // meshToVolume keeps a band 3 voxels to either side of every triangle, wherever it lies, and
  // indexes voxels with int32: a mesh that reaches far beyond the grid (in other units than the
  // volume, or a stray vertex) took gigabytes and minutes for a 16^3 grid, or overflowed
  // OpenVDB's coordinates (the mesh fuzz targets). Such a mesh is refused: it may reach 16 grid
  // extents past the grid, and its surface's band (area in voxels^2 x 7 voxels, ~64 bytes per
  // voxel with OpenVDB's temporaries) must fit in memory.
  const float gridExtent = float(std::max({workDims.x, workDims.y, workDims.z}));
  const float reach = 16.f * gridExtent;
  for (const glm::vec3& p : points)
    if (!(p.x >= -reach && p.y >= -reach && p.z >= -reach && p.x <= float(workDims.x) + reach &&
          p.y <= float(workDims.y) + reach && p.z <= float(workDims.z) + reach))
      throwBadInput(path,
                    "the mesh reaches more than 16 times the grid's size beyond the grid "
                    "(is it in other units than the volume?)");
  double area = 0.0;
  for (const glm::uvec3& t : mesh.triangles)
    area += 0.5 * glm::length(glm::cross(glm::dvec3(points[t.y]) - glm::dvec3(points[t.x]),
                                         glm::dvec3(points[t.z]) - glm::dvec3(points[t.x])));
  if (area * 7.0 * 64.0 > double(availableMemoryBytes()))
    throwBadInput(path, "the mesh's surface spans " + std::to_string(uint64_t(area)) +
                            " voxels^2: its distance band would need more memory than there is");
  std::vector<openvdb::Vec3s> vdbPoints(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    vdbPoints[i] = openvdb::Vec3s(points[i].x, points[i].y, points[i].z);
  std::vector<openvdb::Vec3I> vdbTriangles(mesh.triangles.size());
  for (size_t i = 0; i < vdbTriangles.size(); ++i)
    vdbTriangles[i] = openvdb::Vec3I(mesh.triangles[i].x, mesh.triangles[i].y, mesh.triangles[i].z);

  sdf::reportProgress(progress, path, 0.25f, "distance");
  ProgressInterrupter interrupter(progress, 0.25f, "distance");
  openvdb::FloatGrid::Ptr band;
  openvdb::Int32Grid closest(-1);
  try {
    openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(
        vdbPoints, vdbTriangles);
    const int flags = options.filled ? 0 : openvdb::tools::UNSIGNED_DISTANCE_FIELD;
    band = openvdb::tools::meshToVolume<openvdb::FloatGrid>(interrupter, adapter, *xform, 3.f, 3.f,
                                                            flags, &closest);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorKind::Failure, path + ": out of memory computing the distance field");
  } catch (const std::exception& e) {
    throw Error(ErrorKind::Failure, path + ": distance computation failed: " + e.what());
  }
  if (interrupter.cancelled() || !band) throw Error(ErrorKind::Cancelled, path + ": cancelled");
  vdbPoints = {};
  vdbTriangles = {};
  sdf::reportProgress(progress, path, 0.45f, "distance");

  WorkGrid work(workDims, points, mesh.triangles);
  for (auto it = closest.tree().cbeginValueOn(); it; ++it) {
    const openvdb::Coord c = it.getCoord();
    if (work.contains(c.x(), c.y(), c.z()) && *it >= 0 && size_t(*it) < mesh.triangles.size())
      work.seed(c.x(), c.y(), c.z(), *it);
  }
  if (!work.seeded()) work.seedNearest(workDims.x / 2, workDims.y / 2, workDims.z / 2);
  for (int pass = 0; pass < 6; ++pass) {
    work.propagate(pass % 3);
    sdf::reportProgress(progress, path, 0.45f + 0.35f * float(pass + 1) / 6.f, "distance");
  }

  // Signed (filled) or |u| - d (shell) distance in world units on the work grid.
  std::vector<float> phi(work.size());
  const float h = float(voxel), shell = options.filled ? 0.f : options.shellThickness;
  tbb::parallel_for(tbb::blocked_range<int>(0, workDims.z), [&](const tbb::blocked_range<int>& r) {
    auto accessor = band->getConstAccessor();
    for (int k = r.begin(); k < r.end(); ++k)
      for (int j = 0; j < workDims.y; ++j)
        for (int i = 0; i < workDims.x; ++i) {
          const size_t n = work.index(i, j, k);
          const float d = work.distance(n) * h;
          const bool inside = options.filled && accessor.getValue(openvdb::Coord(i, j, k)) < 0.f;
          phi[n] = (inside ? -d : d) - shell;
        }
  });
  sdf::reportProgress(progress, path, 0.85f, "resample");

  // Onto the dense grid: trilinear in the work grid (exact copies where the voxels coincide).
  Field3D out("sdf", grid, precision, ledger);
  FieldView view(out);
  const glm::vec3 step = grid.spacing / h;
  tbb::parallel_for(tbb::blocked_range<int>(0, grid.dims.z), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k)
      for (int j = 0; j < grid.dims.y; ++j)
        for (int i = 0; i < grid.dims.x; ++i) {
          const glm::vec3 q = glm::clamp(glm::vec3(float(i), float(j), float(k)) * step,
                                         glm::vec3(0.f), glm::vec3(workDims - 1));
          const glm::ivec3 q0 = glm::min(glm::ivec3(q), workDims - 1);
          const glm::ivec3 q1 = glm::min(q0 + 1, workDims - 1);
          glm::vec3 f = q - glm::vec3(q0);
          f = glm::mix(f, glm::round(f),
                       glm::lessThan(glm::abs(f - glm::round(f)), glm::vec3(1e-4f)));
          auto v = [&](int x, int y, int z) { return phi[work.index(x, y, z)]; };
          const float c00 = glm::mix(v(q0.x, q0.y, q0.z), v(q1.x, q0.y, q0.z), f.x);
          const float c10 = glm::mix(v(q0.x, q1.y, q0.z), v(q1.x, q1.y, q0.z), f.x);
          const float c01 = glm::mix(v(q0.x, q0.y, q1.z), v(q1.x, q0.y, q1.z), f.x);
          const float c11 = glm::mix(v(q0.x, q1.y, q1.z), v(q1.x, q1.y, q1.z), f.x);
          view.store(grid.linearIndex(i, j, k),
                     glm::mix(glm::mix(c00, c10, f.y), glm::mix(c01, c11, f.y), f.z));
        }
  });
  sdf::reportProgress(progress, path, 1.f, "resample");
  return out;
}

}  // namespace visopt
