// Zhao's fast sweeping (Math. Comp. 74, 2005) for |grad d| = 1 from a fixed band of known
// distances: Gauss-Seidel sweeps in the 8 diagonal orderings, each voxel taking the smaller of
// its value and the first-order Godunov (upwind) solution from its face neighbours, with the
// grid's own spacing per axis. Rounds of 8 sweeps repeat until a round lowers no voxel by more
// than `tolerance` (world units; cavities and concave parts need a few), at most maxRounds.
// Host code: it runs once per base SDF (sdfFromIsovalue).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace visopt {

// `d`: per voxel (x fastest), the band's distances where `fixed` is set, +infinity (or an upper
// bound) elsewhere; on return every voxel holds its first-order distance from the band.
//
// Rows of one sweep that lie on the same anti-diagonal j + k (in the sweep's order) do not
// touch each other: a row reads its face-neighbour rows (j +- 1, k) and (j, k +- 1), which lie
// on the anti-diagonals before and after. So the anti-diagonals run one after the other and the
// rows on each in parallel, and every voxel sees exactly the neighbour values the serial sweep
// gives it: the result equals fastSweepSerial's bit for bit (tests/unit/test_sdf_building.cpp).
void fastSweep(std::vector<float>& d, const std::vector<uint8_t>& fixed, glm::ivec3 dims,
               glm::vec3 spacing, float tolerance, int maxRounds);

// The reference: the same sweeps, one voxel after the other.
void fastSweepSerial(std::vector<float>& d, const std::vector<uint8_t>& fixed, glm::ivec3 dims,
                     glm::vec3 spacing, float tolerance, int maxRounds);

}  // namespace visopt
