// ghat (kernels/importance_behind.h, Eq. 19) on the CPU backend: one x row of voxels per task in
// chunks of 16, the chunk's positions in both frusta and the trilinear samples of the frustum
// maxima in SIMD lanes (host/frustum_sample_lanes.h), then ImportanceBehind::ghatOf per voxel.
// Compiled by the host compiler alone (src/host); CUDA and the tests' reference run
// ImportanceBehind per voxel.
#pragma once

#include "kernels/importance_behind.h"

namespace visopt {

// Fills k.ghat, timed under `name` (launch items: voxels).
void importanceBehindOnHost(const char* name, const ImportanceBehind& k);

}  // namespace visopt
