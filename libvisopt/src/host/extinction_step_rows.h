// The extinction step (kernels/extinction_step.h, Himmler & Günther 2026, Eqs. 10-14) on the CPU
// backend, one x row of voxels per task in chunks of SIMD lanes: each chunk maps its voxels into
// the view and light frusta together (vectorised: two divisions and a square root per voxel and
// frustum were the latency-bound core of the per-voxel kernel), samples d_V and d_L in lanes too
// (host/frustum_sample_lanes.h: one gather per trilinear corner) and mu_bar one voxel at a time
// (the transfer-function table), then forms the gradient and takes the optimiser step with the
// state's precision fixed at compile time (vectorised). The values are ExtinctionStep's; only the
// order in which the sums add up differs. Compiled by the host compiler alone (src/host); the CUDA
// backend and the tests' reference run ExtinctionStep, one voxel per thread.
#pragma once

#include "kernels/extinction_step.h"

namespace visopt {

// The step on the calling thread's oneTBB arena, timed under `name` (launch items: voxels).
// Any mix of precisions is accepted; the fast form needs mu and the optimiser state in one
// precision and falls back to ExtinctionStep per voxel otherwise.
StepSums extinctionStepOnHost(const char* name, const ExtinctionStep& step);

}  // namespace visopt
