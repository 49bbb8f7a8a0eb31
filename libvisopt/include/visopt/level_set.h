// Settings and statistics of the context-surface optimisation (Himmler & Günther 2026, §III-B-D,
// Eqs. 18-23, Alg. 1): level-set propagation of the SDF phi towards where it hides nothing
// important and back to its base shape phi0 elsewhere.
#pragma once

#include <cstdint>

namespace visopt {

struct LevelSetSettings {
  // Eq. 23: phi_t = max(0, ghat |grad phi| kappa + grad ghat . grad phi) + lambda(x) (phi0 - phi),
  // lambda(x) = max(0, lambda - ghat(x)).
  float lambda = 0.3f;
  float curvatureEpsilon = 1e-6f;  // in the curvature's denominator (docs/methods.md §3)
  // Explicit Euler: each step uses cfl times the largest stable time step (docs/methods.md §3),
  // and at least `substeps` such steps run per optimisation iteration.
  float cfl = 0.5f;
  int substeps = 4;
  // How far surfaces can travel in one optimisation run. The curvature term moves a surface of
  // radius R at speed ghat / R, and the stable step is ~dx^2 / 6, so a fixed number of substeps
  // moves a head-sized surface by a fraction of a voxel per iteration: on a CT skin (R ~ 50
  // coarse voxels) 60 iterations of 4 substeps dent it by ~0.4 voxel where it should give way
  // by tens. With reach > 0 the optimiser runs, per iteration of the coarsest level, enough
  // substeps that over its iteration cap mean-curvature flow at ghat = 1/2 could shrink a sphere
  // of reach x the volume's bounding radius to a point (time reach^2 R^2 / 2); finer levels run
  // (h_coarsest / h)^2 as many, i.e. polish what the coarse levels moved. 0: `substeps` only.
  float reach = 1.f;
  // Redistancing (Eq. 18): at most this many iterations, stopping early when the mean squared
  // change per iteration falls below the tolerance (in voxel units squared).
  int redistanceIterations = 64;
  float redistanceTolerance = 1e-4f;
  // Accuracy of the upwinded one-sided differences in Godunov's |grad phi| (the curvature
  // term's and redistancing's): 1 = first order, 2 = second-order ENO (the default; first
  // order biases the speed of a sphere of radius r by ~0.6 dx / r and leaves |grad phi| off by
  // as much after redistancing).
  int spatialOrder = 2;
  // The narrow band, in voxels: the level-set step and redistancing run only over the bricks of
  // 8^3 voxels that hold a voxel within this distance of the surface or of its base shape phi0,
  // or where phi and phi0 differ in sign (the region a surface swept, where the return term of
  // Eq. 23 can flip the sign back); the rest of the grid keeps its values, of which only the
  // sign is read there. Stale values at the band's edge reach the surface through the
  // stencils (two voxels per substep, damped like diffusion): on mean-curvature flow of a
  // sphere the zero sets of the band and dense paths lie 0.08 voxel apart at 6, 0.005 at 8 and
  // 10 (tests/unit/test_level_set_band.cpp), so 8. 0: every voxel, the dense reference path
  // (which the CUDA backend also takes for now).
  float band = 8.f;
  // How each iteration integrates Eq. 23 over the time its substeps cover (substeps x the stable
  // explicit dt). false: explicit Euler substeps (Eq. 25, Alg. 1; the reference). true: one
  // semi-implicit step per chunk of substeps (kernels/implicit_diffusion.h: the occlusion term as
  // div(ghat grad phi), valid where phi is a distance field, in one-dimensional implicit solves
  // along x, y and z, then Eq. 23's clamp and the return term's exact decay): stable at any step,
  // so a chunk that moves a surface half a voxel costs four passes over the band instead of up to
  // hundreds of substeps.
  bool semiImplicit = true;
};

// Half-width, in voxels, of the band around the surface whose motion LevelSetStepStats reports
// (|phi| within a voxel: where the zero level set lies; an opened region's positive phi keeps
// rising under the curvature term without any surface moving).
constexpr float kNearSurfaceBand = 1.f;

// Throws Error(Usage) naming the setting unless every value is finite and in its range.
void checkLevelSetSettings(const LevelSetSettings& settings);

struct LevelSetStepStats {
  double timeStep = 0.0;  // dt of one substep
  int substeps = 0;
  double maxChange = 0.0;  // max |delta phi| of one substep, world units
  // How far the surface itself moved in one substep: the largest |delta phi| x (1 - |phi| / dx)
  // over voxels within kNearSurfaceBand voxels of the surface (the share of a change at a voxel
  // that moves the zero set on its edges; kernels/level_set_step.h surfaceShare). The far
  // field's kinks move faster, and matter only when a surface comes near them.
  double nearMaxChange = 0.0;
  // max rise of phi of one substep over voxels inside the surface beyond kNearSurfaceBand: how
  // fast a kink of the inside can come up towards zero (ChangeSums::insideRiseMax).
  double insideRise = 0.0;
  double meanChange = 0.0;    // mean |delta phi| per substep
  int64_t bandVoxels = 0;     // voxels of the band (0: the whole grid)
  int64_t workVoxels = 0;     // of which the step ran over (the band less its fixed bricks)
  bool hasInterface = false;  // phi has a surface after the step (a sign change somewhere)
};

struct RedistanceStats {
  int iterations = 0;
  double meanSquaredChange = 0.0;  // of the last iteration, in voxel units squared
  bool converged = false;          // stopped early below the tolerance
  int64_t bandVoxels = 0;          // voxels of the band (0: the whole grid)
  int64_t workVoxels = 0;          // of which redistancing ran over (less the fixed bricks)
};

}  // namespace visopt
