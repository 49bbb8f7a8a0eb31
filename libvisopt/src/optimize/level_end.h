// When a coarse-to-fine level has settled and the optimiser moves to the next one.
//
// Two ways to settle:
//  1. Converged: the energy's relative change in the last iteration is below the tolerance and
//     the surfaces have stopped (they moved under a tenth of a voxel, or their deviation from
//     the base is steady from one iteration to the next).
//  2. A limit cycle: with context surfaces the optimisation can circle instead of converging.
//     The level-set step moves a surface through the iteration's ghat, the next view scan sees
//     the new surface and changes ghat, and the surface moves back: on the Cranium CT (README
//     command) the coarsest level repeated the same seven iterations (energy within 0.9 %,
//     the surfaces' mean and largest deviation to the third decimal) from iteration 31 to its
//     cap of 60, and the middle level a four-iteration cycle from 22 to 60, while the energy
//     drifted by ~1e-4 per iteration, just above the tolerance of test 1. Over the last window
//     of iterations such a level makes little progress against how much the energy moves back
//     and forth, and the surfaces' deviation shows no trend against the window before.
#pragma once

#include <span>

#include "visopt/optimization.h"

namespace visopt {

// Iterations per window of the cycle test: longer than the cycles seen (seven iterations).
inline constexpr int kLevelCycleWindow = 8;

// `level`: this level's iterations so far, oldest first.
bool levelConverged(std::span<const IterationStats> level, const ExtinctionSettings& s);
// levelInCycle: visopt/optimization.h.
inline bool levelSettled(std::span<const IterationStats> level, const ExtinctionSettings& s) {
  return levelConverged(level, s) || levelInCycle(level, s);
}

}  // namespace visopt
