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
void restrictSdf(const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  const FieldView from(src), to(dst);
  const GridMap map(dst.grid());
  exec::parallelFor("multigrid restrict sdf", int64_t(dst.size()), [=] VISOPT_HD(int64_t v) {
    const auto [i, j, k] = map.ijk(v);
    float m = 3.0e38f;
    for (int c = 0; c < kRestrictionSamples; ++c)
      m = fminf(m, from.sample(srcMap.toIndex(restrictionSample(map, i, j, k, c))));
    to.store(size_t(v), m);
  });
}

void restrictMean(const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  const FieldView from(src), to(dst);
  const GridMap map(dst.grid());
  exec::parallelFor("multigrid restrict mean", int64_t(dst.size()), [=] VISOPT_HD(int64_t v) {
    const auto [i, j, k] = map.ijk(v);
    float sum = 0.f;
    for (int c = 0; c < kRestrictionSamples; ++c)
      sum += from.sample(srcMap.toIndex(restrictionSample(map, i, j, k, c)));
    to.store(size_t(v), sum / float(kRestrictionSamples));
  });
}

void restrictMax(const Field3D& src, const GridMap& srcMap, Field3D& dst) {
  const FieldView from(src), to(dst);
  const GridMap map(dst.grid());
  exec::parallelFor("multigrid restrict max", int64_t(dst.size()), [=] VISOPT_HD(int64_t v) {
    const auto [i, j, k] = map.ijk(v);
    float m = -3.0e38f;
    for (int c = 0; c < kRestrictionSamples; ++c)
      m = fmaxf(m, from.sample(srcMap.toIndex(restrictionSample(map, i, j, k, c))));
    to.store(size_t(v), m);
  });
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

double prolongChange(const Field3D& now, const Field3D& before, const GridMap& coarse,
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

}  // namespace visopt
