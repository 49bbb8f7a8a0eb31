// Host side of the volume's ambient occlusion (kernels/volume_occlusion.h): three passes per
// axis over the volume's grid, with scratch of three floats per voxel released on return.
#include <cmath>
#include <string>

#include "core/device_buffer.h"
#include "core/field_view.h"
#include "exec/parallel.h"
#include "kernels/volume_occlusion.h"
#include "render/renderer.h"
#include "visopt/error.h"
#include "visopt/exec.h"

namespace visopt {

void computeVolumeOcclusion(const RenderScene& scene, RenderMethod method, float cutThreshold,
                            float radius, Field3D& out) {
  if (!scene.volume || !scene.transfer) throw Error(ErrorKind::Usage, "nothing to occlude");
  const GridSpec& grid = scene.volume->grid();
  if (out.grid().dims != grid.dims)
    throw Error(ErrorKind::Failure, "the volume occlusion field is not on the volume's grid");
  if (!(radius >= 0.f && std::isfinite(radius)))
    throw Error(ErrorKind::Usage, "the ambient occlusion radius must be finite and >= 0");
  const glm::ivec3 dims = grid.dims;
  const int64_t n = int64_t(dims.x) * dims.y * dims.z;

  OcclusionExtinctionPerVoxel perVoxel;
  perVoxel.extinction.scalars = FieldView(scene.volume->normalized);
  if (scene.extinctionChange) perVoxel.extinction.change = FieldView(*scene.extinctionChange);
  perVoxel.extinction.transfer =
      TransferLookup{scene.transfer->data(), int(scene.transfer->size())};
  if (scene.extinctionChange && scene.extinctionChange->grid().dims != dims)
    throw Error(ErrorKind::Failure, "the extinction change is not on the volume's grid");
  // The maximum importance projection's AO sees the volume only, as its T_L does.
  const size_t surfaceCount =
      method == RenderMethod::MaxImportanceProjection ? 0 : scene.surfaces.size();
  for (size_t i = 0; i < surfaceCount && i < size_t(kMaxContextSurfaces); ++i) {
    if (scene.surfaces[i]->grid().dims != dims)
      throw Error(ErrorKind::Failure, "a context surface is not on the volume's grid");
    perVoxel.surfaces.phi[perVoxel.surfaces.count++] = FieldView(*scene.surfaces[i]);
  }
  perVoxel.method = static_cast<RayMethod>(static_cast<int>(method));
  if ((method == RenderMethod::CutAway || method == RenderMethod::TransparencyModulation) &&
      !perVoxel.surfaces.empty()) {
    if (!scene.importanceBehind || scene.importanceBehind->grid().dims != dims)
      throw Error(ErrorKind::Usage, std::string("the ") + toString(method) +
                                        " baseline's occlusion needs ghat on the volume's grid");
    perVoxel.importanceBehind = FieldView(*scene.importanceBehind);
  }
  perVoxel.cutThreshold = cutThreshold;
  perVoxel.cap = kOcclusionMaxDepthPerVoxel / grid.minSpacing();
  DeviceBuffer<float> mu(static_cast<size_t>(n)), prefix(static_cast<size_t>(n)),
      sum(static_cast<size_t>(n));
  perVoxel.mu = mu.data();
  exec::parallelFor("volume occlusion: extinction", n, perVoxel);

  for (int axis = 0; axis < 3; ++axis) {
    OcclusionPrefixRows rows;
    rows.dims = dims;
    rows.axis = axis;
    rows.spacing = grid.spacing[axis];
    rows.mu = mu.data();
    rows.prefix = prefix.data();
    // Along y and z the CPU backend sweeps groups of side-by-side rows (contiguous runs); one
    // thread per row is what the device runs (adjacent threads read adjacent elements).
    if (axis == 0 || activeBackend() == Backend::CUDA) {
      exec::parallelFor("volume occlusion: prefix", n / dims[axis], rows);
    } else {
      const OcclusionPrefixRowGroups groups{rows};
      exec::parallelFor("volume occlusion: prefix", groups.groups(), groups);
    }

    OcclusionAccumulate acc;
    acc.dims = dims;
    acc.axis = axis;
    acc.reach = radius / grid.spacing[axis];
    acc.spacing = grid.spacing[axis];
    acc.mu = mu.data();
    acc.prefix = prefix.data();
    acc.sum = sum.data();
    acc.firstAxis = axis == 0;
    if (axis == 2) acc.out = FieldView(out);
    exec::parallelFor("volume occlusion: accumulate", n, acc);
  }
}

}  // namespace visopt
