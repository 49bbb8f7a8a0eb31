// Settings and statistics of the context-surface optimisation (paper 000 §III-B-D, Eqs. 18-23,
// Alg. 1): level-set propagation of the SDF phi towards where it hides nothing important and
// back to its base shape phi0 elsewhere.
#pragma once

namespace visopt {

struct LevelSetSettings {
  // Eq. 23: phi_t = max(0, ghat |grad phi| kappa + grad ghat . grad phi) + lambda(x) (phi0 - phi),
  // lambda(x) = max(0, lambda - ghat(x)).
  float lambda = 0.3f;
  float curvatureEpsilon = 1e-6f;  // in the curvature's denominator (METHODS.md §3)
  // Explicit Euler: each step uses cfl times the largest stable time step (METHODS.md §3),
  // and `substeps` such steps run per optimisation iteration.
  float cfl = 0.5f;
  int substeps = 4;
  // Redistancing (Eq. 18): at most this many iterations, stopping early when the mean squared
  // change per iteration falls below the tolerance (in voxel units squared).
  int redistanceIterations = 64;
  float redistanceTolerance = 1e-4f;
  // Accuracy of the upwinded one-sided differences in Godunov's |grad phi| (the curvature
  // term's and redistancing's): 1 = first order, 2 = second-order ENO (the default; first
  // order biases the speed of a sphere of radius r by ~0.6 dx / r and leaves |grad phi| off by
  // as much after redistancing).
  int spatialOrder = 2;
};

struct LevelSetStepStats {
  double timeStep = 0.0;  // dt of one substep
  int substeps = 0;
  double maxChange = 0.0;   // max |delta phi| of one substep, world units
  double meanChange = 0.0;  // mean |delta phi| per substep
};

struct RedistanceStats {
  int iterations = 0;
  double meanSquaredChange = 0.0;  // of the last iteration, in voxel units squared
  bool converged = false;          // stopped early below the tolerance
};

}  // namespace visopt
