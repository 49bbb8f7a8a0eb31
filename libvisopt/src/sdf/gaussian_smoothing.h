// A separable Gaussian blur of a scalar field, host code for building base SDFs
// (sdfFromIsovalue's pre-smoothing; optimize/level_set.h says why and how much).
#pragma once

#include "visopt/field.h"

namespace visopt {

class MemoryLedger;

// `in` convolved with a Gaussian of standard deviation sigma voxels along each axis (in that
// axis's own voxels), truncated at ceil(3 sigma) voxels and normalised to sum 1; edge voxels
// repeat beyond the faces. An axis of one voxel is left as it is. fp32 result (named
// "sdf-smoothed-scalar" in the ledger), whatever in's precision. sigma > 0.
Field3D gaussianSmoothed(const Field3D& in, float sigma, MemoryLedger* ledger);

}  // namespace visopt
