#include "optimize/multigrid_transfer.h"

#include <algorithm>
#include <cmath>

#include "core/field_view.h"
#include "exec/parallel.h"
#include "kernels/transfer_lookup.h"

namespace visopt {

GridSpec levelGrid(const GridSpec& fine, int factor) {
  if (factor <= 1) return fine;
  GridSpec g = fine;
  for (int a = 0; a < 3; ++a) {
    if (fine.dims[a] <= 2) continue;
    g.dims[a] = std::max(2, (fine.dims[a] - 1 + factor - 1) / factor + 1);
    g.spacing[a] = fine.spacing[a] * float(fine.dims[a] - 1) / float(g.dims[a] - 1);
  }
  return g;
}

// Trilinear resampling of `src` (on the grid `srcMap`) onto `dst`'s grid.
void resample(const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  const FieldView from(src), to(dst);
  const GridMap map(dst.grid());
  exec::parallelFor("multigrid resample", int64_t(dst.size()), [=] VISOPT_HD(int64_t v) {
    const auto [i, j, k] = map.ijk(v);
    to.store(size_t(v),
             from.sample(srcMap.toIndex(map.toWorld(glm::vec3(float(i), float(j), float(k))))));
  });
}

// The world mask on a coarser grid: a coarse voxel is masked where the trilinear interpolation
// of the fine 0/1 mask at its centre exceeds 0.5 (what resampling the mask as a field and
// thresholding it gave). One work item per output byte, so no two write the same word.
void resampleMask(const DeviceBitMask& src, const GridMap& srcMap, DeviceBitMask& dst,
                  const GridSpec& dstGrid) {
  const BitMaskView from = src.view();
  uint8_t* to = dst.words();
  const GridMap map(dstGrid);
  const int64_t voxels = int64_t(dstGrid.voxelCount());
  exec::parallelFor("multigrid resample mask", int64_t(dst.bytes()), [=] VISOPT_HD(int64_t b) {
    unsigned word = 0;
    for (int bit = 0; bit < 8; ++bit) {
      const int64_t v = b * 8 + bit;
      if (v >= voxels) break;
      const auto [i, j, k] = map.ijk(v);
      const glm::vec3 p = srcMap.toIndex(map.toWorld(glm::vec3(float(i), float(j), float(k))));
      if (from.sample(p) > 0.5f) word |= 1u << bit;
    }
    to[b] = static_cast<uint8_t>(word);
  });
}

// Prolongation of a surface's deviation: phi_fine = phi0_fine + (phi_coarse - phi0_coarse),
// trilinear. Prolonging phi itself would replace the fine base shape by the coarse level's
// blurred (min-restricted) one wherever nothing moved, leaving voxel-scale ripples for the slow
// return term to remove.
void prolongDeviation(const Field3D& phiCoarse, const Field3D& baseCoarse, const GridMap& coarse,
                      const Field3D& baseFine, Field3D& phiFine) {
  const FieldView pc(phiCoarse), bc(baseCoarse), bf(baseFine), out(phiFine);
  const GridMap map(phiFine.grid());
  exec::parallelFor("multigrid prolong sdf", int64_t(phiFine.size()), [=] VISOPT_HD(int64_t v) {
    const auto [i, j, k] = map.ijk(v);
    const glm::vec3 q = coarse.toIndex(map.toWorld(glm::vec3(float(i), float(j), float(k))));
    out.store(size_t(v), bf.load(size_t(v)) + (pc.sample(q) - bc.sample(q)));
  });
}

// Restriction of an SDF to a coarser grid: the minimum over 3^3 points spread over each coarse
// voxel, so a surface thinner than a coarse voxel (a skull, a thin shell) does not vanish from
// the coarse levels, where it would otherwise let the view through.
namespace {

// The three restrictions differ only in how they reduce the 27 samples of a coarse voxel.
enum class Reduction { Min, Mean, Max };

template <Reduction R>
void restrictBy(const char* name, const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  const FieldView from(src), to(dst);
  const GridMap map(dst.grid());
  exec::parallelFor(name, int64_t(dst.size()), [=] VISOPT_HD(int64_t v) {
    const auto [i, j, k] = map.ijk(v);
    float acc = R == Reduction::Min ? 3.0e38f : (R == Reduction::Max ? -3.0e38f : 0.f);
    for (int c = 0; c < kRestrictionSamples; ++c) {
      const float s = from.sample(srcMap.toIndex(restrictionSample(map, i, j, k, c)));
      if constexpr (R == Reduction::Min)
        acc = fminf(acc, s);
      else if constexpr (R == Reduction::Max)
        acc = fmaxf(acc, s);
      else
        acc += s;
    }
    to.store(size_t(v), R == Reduction::Mean ? acc / float(kRestrictionSamples) : acc);
  });
}

}  // namespace

void restrictSdf(const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  restrictBy<Reduction::Min>("multigrid restrict sdf", src, srcMap, dst);
}

void restrictMean(const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  restrictBy<Reduction::Mean>("multigrid restrict mean", src, srcMap, dst);
}

void restrictMax(const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  restrictBy<Reduction::Max>("multigrid restrict max", src, srcMap, dst);
}

void restrictBaseAndImportance(const Field3D& scalarField, const DeviceBuffer<glm::vec4>& table,
                               const Field3D& importance, const GridMap& fineMap,
                               Field3D& baseCoarse, Field3D& importanceCoarse) {
  FieldView base(baseCoarse), imp(importanceCoarse);
  const FieldView scalars(scalarField), fineImp(importance);
  const TransferLookup tf{table.data(), int(table.size())};
  const GridMap map(baseCoarse.grid());
  exec::parallelFor("multigrid restrict", int64_t(baseCoarse.size()), [=] VISOPT_HD(int64_t v) {
    const auto [i, j, k] = map.ijk(v);
    float b = 0.f, g = 0.f;
    for (int c = 0; c < kRestrictionSamples; ++c) {
      const glm::vec3 fi = fineMap.toIndex(restrictionSample(map, i, j, k, c));
      b += tf.at(scalars.sample(fi)).w;
      g += fineImp.sample(fi);
    }
    base.store(size_t(v), b / float(kRestrictionSamples));
    imp.store(size_t(v), g / float(kRestrictionSamples));
  });
}

double prolongChangeReference(const Field3D& now, const Field3D& before, const GridMap& coarse,
                              Field3D& fine, float lo, float hi) {
  const FieldView a(now), b(before), out(fine);
  const GridMap map(fine.grid());
  return exec::reduce(
      "multigrid coarse correction", int64_t(fine.size()), 0.0,
      [=] VISOPT_HD(int64_t v) {
        const auto [i, j, k] = map.ijk(v);
        const glm::vec3 q = coarse.toIndex(map.toWorld(glm::vec3(float(i), float(j), float(k))));
        const float change = a.sample(q) - b.sample(q);
        if (change == 0.f) return 0.0;
        const float old = out.load(size_t(v));
        const float next = fminf(fmaxf(old + change, lo), hi);
        out.store(size_t(v), next);
        return double(fabsf(next - old));
      },
      [] VISOPT_HD(double x, double y) { return x > y ? x : y; });
}

namespace {

// The trilinear weights along one axis at coarse index q, clamped to the grid as
// FieldView::sample does.
struct AxisWeights {
  int i0, i1;
  float f;
};
VISOPT_HD VISOPT_INLINE AxisWeights axisWeights(float q, int n) {
  q = q > 0.f ? (q < float(n - 1) ? q : float(n - 1)) : 0.f;  // no libm call in the loop
  AxisWeights a;
  a.i0 = int(q);
  a.i1 = a.i0 + 1 < n ? a.i0 + 1 : n - 1;
  a.f = q - float(a.i0);
  return a;
}

}  // namespace

double prolongChange(const Field3D& now, const Field3D& before, const GridMap& coarse,
                     Field3D& fine, float lo, float hi) {
  const GridMap map(fine.grid());
  // fine voxel (i, j, k) -> coarse index q0 + (i ax, j ay, k az) when the axes map onto axes.
  const glm::vec3 q0 = coarse.toIndex(map.toWorld(glm::vec3(0.f)));
  const glm::vec3 ax = coarse.toIndex(map.toWorld(glm::vec3(1.f, 0.f, 0.f))) - q0;
  const glm::vec3 ay = coarse.toIndex(map.toWorld(glm::vec3(0.f, 1.f, 0.f))) - q0;
  const glm::vec3 az = coarse.toIndex(map.toWorld(glm::vec3(0.f, 0.f, 1.f))) - q0;
  const float off =
      fabsf(ax.y) + fabsf(ax.z) + fabsf(ay.x) + fabsf(ay.z) + fabsf(az.x) + fabsf(az.y);
  if (!(off < 1e-5f) || now.grid().dims != coarse.dims || before.grid().dims != coarse.dims)
    return prolongChangeReference(now, before, coarse, fine, lo, hi);

  const glm::ivec3 cd = coarse.dims, fd = map.dims;
  const int64_t coarseCount = int64_t(cd.x) * cd.y * cd.z;
  DeviceBuffer<float> diff(static_cast<size_t>(coarseCount));
  DeviceBuffer<uint8_t> rowChanged(static_cast<size_t>(int64_t(cd.y) * cd.z));
  {
    const FieldView a(now), b(before);
    float* d = diff.data();
    uint8_t* changed = rowChanged.data();
    exec::parallelFor("multigrid correction: coarse change", int64_t(cd.y) * cd.z,
                      [=] VISOPT_HD(int64_t row) {
                        uint8_t any = 0;
                        for (int i = 0; i < cd.x; ++i) {
                          const size_t c = size_t(row * cd.x + i);
                          const float v = a.load(c) - b.load(c);
                          d[c] = v;
                          any |= v != 0.f ? 1 : 0;
                        }
                        changed[row] = any;
                      });
  }
  // The x weights are the same in every row.
  DeviceBuffer<AxisWeights> xWeights(static_cast<size_t>(fd.x));
  for (int i = 0; i < fd.x; ++i) xWeights[size_t(i)] = axisWeights(q0.x + float(i) * ax.x, cd.x);
  const AxisWeights* xw = xWeights.data();
  const FieldView out(fine);
  const float* d = diff.data();
  const uint8_t* changed = rowChanged.data();
  return exec::reduce(
      "multigrid correction: fine rows", int64_t(fd.y) * fd.z, 0.0,
      [=] VISOPT_HD(int64_t row) {
        const int j = int(row % fd.y), k = int(row / fd.y);
        const AxisWeights y = axisWeights(q0.y + float(j) * ay.y, cd.y);
        const AxisWeights z = axisWeights(q0.z + float(k) * az.z, cd.z);
        const int64_t r00 = int64_t(z.i0) * cd.y + y.i0, r10 = int64_t(z.i0) * cd.y + y.i1;
        const int64_t r01 = int64_t(z.i1) * cd.y + y.i0, r11 = int64_t(z.i1) * cd.y + y.i1;
        if (!(changed[r00] | changed[r10] | changed[r01] | changed[r11])) return 0.0;
        const float* c00 = d + r00 * cd.x;
        const float* c10 = d + r10 * cd.x;
        const float* c01 = d + r01 * cd.x;
        const float* c11 = d + r11 * cd.x;
        double most = 0.0;
        const size_t base = size_t(row) * size_t(fd.x);
        for (int i = 0; i < fd.x; ++i) {
          const AxisWeights x = xw[i];
          const float e00 = c00[x.i0] + x.f * (c00[x.i1] - c00[x.i0]);
          const float e10 = c10[x.i0] + x.f * (c10[x.i1] - c10[x.i0]);
          const float e01 = c01[x.i0] + x.f * (c01[x.i1] - c01[x.i0]);
          const float e11 = c11[x.i0] + x.f * (c11[x.i1] - c11[x.i0]);
          const float e0 = e00 + y.f * (e10 - e00), e1 = e01 + y.f * (e11 - e01);
          const float change = e0 + z.f * (e1 - e0);
          if (change == 0.f) continue;
          const float old = out.load(base + size_t(i));
          const float sum = old + change;
          const float next = sum > lo ? (sum < hi ? sum : hi) : lo;
          out.store(base + size_t(i), next);
          const double moved = double(fabsf(next - old));
          most = moved > most ? moved : most;
        }
        return most;
      },
      [] VISOPT_HD(double x, double y) { return x > y ? x : y; });
}

}  // namespace visopt
