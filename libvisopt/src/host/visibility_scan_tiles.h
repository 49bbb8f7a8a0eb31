// The fast visibility scan on the CPU backend, one tile of kTileRays adjacent rays per task (the
// tiles of core/frustum_field.h): each ray's front-to-back pass as in FastVisibilityScan (its
// samples are gathers: scalar), into a buffer laid out like the tile; then the back-to-front pass
// of the tile's rays together, depth by depth, in SIMD lanes, storing one 64-byte row of d (and of
// the running maximum of g) per depth where the per-ray pass stored one value per cache line.
// Compiled by the host compiler alone, also in CUDA-enabled builds (src/host is no device
// source); the CUDA backend runs FastVisibilityScan, one thread per ray.
#pragma once

#include "kernels/visibility_scan.h"

namespace visopt {

// The scan on the calling thread's oneTBB arena, timed under `name` (launch items: rays). Rays
// of at most kScanBufferCells depth cells (kernels/visibility_scan_fast.h).
ScanSums scanTilesOnHost(const char* name, const VisibilityScan& scan);

}  // namespace visopt
