// The multigrid's transfer operators between the levels of the extinction optimiser
// (Himmler & Günther 2026, §II-C: coarse to fine; optimize/extinction_optimizer.h): the level
// grids, restriction of fields and SDFs to a coarser grid, prolongation back, and the coarse-grid
// correction of the camera-following iterations (ExtinctionOptimizer::follow).
#pragma once

#include <glm/glm.hpp>

#include "core/device_bit_mask.h"
#include "core/device_buffer.h"
#include "core/frustum_map.h"
#include "core/hd.h"
#include "visopt/field.h"

namespace visopt {

// The grid of a level `factor` times coarser than `fine` (the same world box; at least 2 voxels
// per axis, axes of 1-2 voxels kept).
GridSpec levelGrid(const GridSpec& fine, int factor);

// The world position of sample c (0..26) of the 3^3 samples that restriction takes in coarse
// voxel (i, j, k): the voxel's centre and the points a third of a voxel from it along each axis.
VISOPT_HD VISOPT_INLINE glm::vec3 restrictionSample(const GridMap& coarse, int i, int j, int k,
                                                    int c) {
  const glm::vec3 off(float(c % 3 - 1), float((c / 3) % 3 - 1), float(c / 9 - 1));
  return coarse.toWorld(glm::vec3(float(i), float(j), float(k)) + off / 3.f);
}
inline constexpr int kRestrictionSamples = 27;

// Trilinear resampling of `src` (on the grid `srcMap`) onto `dst`'s grid.
void resample(const Field3D& src, const GridMap& srcMap, Field3D& dst);
// The world mask on a coarser grid (masked where the interpolated 0/1 mask exceeds 0.5).
void resampleMask(const DeviceBitMask& src, const GridMap& srcMap, DeviceBitMask& dst,
                  const GridSpec& dstGrid);
// phi_fine = phi0_fine + (phi_coarse - phi0_coarse), trilinear (see the definition).
void prolongDeviation(const Field3D& phiCoarse, const Field3D& baseCoarse, const GridMap& coarse,
                      const Field3D& baseFine, Field3D& phiFine);
// The minimum over the restriction samples of each coarse voxel (see the definition).
void restrictSdf(const Field3D& src, const GridMap& srcMap, Field3D& dst);
// The mean over the restriction samples of each coarse voxel of `dst`.
void restrictMean(const Field3D& src, const GridMap& srcMap, Field3D& dst);
// The maximum over the restriction samples of each coarse voxel of `dst`.
void restrictMax(const Field3D& src, const GridMap& srcMap, Field3D& dst);
// The coarse mu_bar (the transfer function's extinction of the scalars) and importance: means
// over the restriction samples, as the coarse levels of the multigrid use them.
void restrictBaseAndImportance(const Field3D& scalars, const DeviceBuffer<glm::vec4>& transfer,
                               const Field3D& importance, const GridMap& fineMap,
                               Field3D& baseCoarse, Field3D& importanceCoarse);
// The coarse-grid correction: fine += the trilinear prolongation of (now - before), both on the
// grid `coarse`, clamped to [lo, hi]. Returns the largest |change| applied.
// The fast path: the difference taken once on the coarse grid (fp32), the fine voxels visited by
// rows with the coarse index along each axis from one multiply-add, and rows whose four coarse
// rows carry no change skipped (a followed camera changes mu and phi only where the view
// moved). Grids whose axes do not map onto each other's axes (never, for levelGrid's) take the
// reference path.
double prolongChange(const Field3D& now, const Field3D& before, const GridMap& coarse,
                     Field3D& fine, float lo, float hi);
// The reference: per fine voxel, its world position sampled in `now` and in `before`.
double prolongChangeReference(const Field3D& now, const Field3D& before, const GridMap& coarse,
                              Field3D& fine, float lo, float hi);

}  // namespace visopt
