// Host orchestration of the context-surface numerics (Himmler & Günther 2026, §III-B-D;
// docs/methods.md §3): the level-set step of Eq. 23, redistancing (Eq. 18), an SDF from an
// isovalue, thin shells (Eq. 26). Fields are fp32 or fp16 (each Field3D's own precision);
// arithmetic is fp32.
#pragma once

#include "visopt/field.h"
#include "visopt/level_set.h"
#include "visopt/precision.h"
#include "visopt/volume.h"

namespace visopt {

class MemoryLedger;
class DeviceBitMask;
class NarrowBand;

// s.substeps explicit Euler substeps of Eq. 23 on phi, or with s.semiImplicit one
// semi-implicit step over the same time (kernels/implicit_diffusion.h; the statistics then per
// substep's worth of it), in place; `scratch` is the second buffer, (re)allocated like phi when
// it does not match phi's grid and precision. Each
// substep's dt = s.cfl x min(dx / max|grad ghat|, dx^2 / (6 max ghat), 1 / max lambda(x)),
// dx the smallest spacing; terms whose maximum is 0 drop out, and dt is at most s.cfl x dx^2
// (world units) when all of them do. s.cfl is clamped to (0, 1]. `mask` (nullable; a set bit =
// masked) turns the occlusion term off. phi0, ghat and mask must be on phi's grid.
// On the band path (LevelSetSettings::band > 0, CPU backend) `band` (nullable) is the surface's
// narrow band kept between calls (built on first use, moved with the surface after the step);
// without one each call finds the band by a pass over the whole grid.
LevelSetStepStats levelSetStep(Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                               const DeviceBitMask* mask, const LevelSetSettings& s,
                               Field3D& scratch, NarrowBand* band = nullptr);

// Every value of `from` into `to` (the same grid; either precision), in parallel.
void copyField(const Field3D& from, Field3D& to);

// The stable dt levelSetStep would use (the same formula), for tests and callers.
double levelSetTimeStep(const Field3D& ghat, const LevelSetSettings& s);

// Up to s.redistanceIterations iterations of Eq. 18 on phi (in place; scratch as above),
// stopping early when the mean squared change per iteration (voxel units^2) falls below
// s.redistanceTolerance; see kernels/redistance.h for the scheme (subcell fix at the interface,
// dtau). A field without any sign change has no interface to measure distance
// from: it is left unchanged (0 iterations, converged). With `base` (the surface's phi0, on
// phi's grid) every voxel within kRedistanceKeepsBaseWithin voxels of phi0 keeps its value:
// only where the surface moved is it redistanced, and elsewhere it stays exactly in place.
// True when phi changes sign between two neighbouring voxels somewhere (it has a surface).
bool hasInterface(const Field3D& phi);

// With stopBand > 0 the early stop measures the mean squared change over the voxels within
// stopBand voxels of the surface only (|phi| <= stopBand dx before the pass), where the joint
// loop needs the distance: over the whole box, regions far from every surface that are still
// converging (a region a surface left) hold every call to its iteration cap.
inline constexpr float kRedistanceKeepsBaseWithin = 0.05f;
// The stopBand the joint loop's redistancing and sdfFromIsovalue's polish measure settling over:
// the voxels within 3 of the surface, where the level-set step needs a distance.
inline constexpr float kRedistanceStopBandVoxels = 3.f;
// `band` as for levelSetStep (one built there with phi0 serves a call without `base`).
RedistanceStats redistance(Field3D& phi, const LevelSetSettings& s, Field3D& scratch,
                           const Field3D* base = nullptr, float stopBand = 0.f,
                           NarrowBand* band = nullptr);

// Single passes, for the benchmark: one Euler substep of Eq. 23 with a given dt from `phi`
// into `out` (returns max |delta phi|), and one redistancing iteration from `in` into `out`
// (returns the mean squared change in voxel units^2; the interface band is copied).
double levelSetSubstep(const Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                       const DeviceBitMask* mask, const LevelSetSettings& s, double dt,
                       Field3D& out);
double redistanceIteration(const Field3D& in, Field3D& out, int spatialOrder = 2);

// On the band path, builds `band` for phi if needed and marks its bricks that the step with
// this ghat and redistancing against phi0 leave unchanged (NarrowBand::markFixed), which the
// next levelSetStep and redistance calls with the same ghat and phi0 skip. Call whenever ghat's
// values change. Nothing happens on the dense path.
void markFixedBricks(Field3D& phi, const Field3D& phi0, const Field3D& ghat,
                     const LevelSetSettings& s, NarrowBand& band);

// The default Gaussian pre-smoothing of sdfFromIsovalue, sigma in voxels (see there).
inline constexpr float kIsoPresmoothSigma = 0.85f;

// phi(x, 0) = +-(s~(x) - iso) / |grad s~| (inside negative: with insideHigh, values above the
// isovalue are inside), |grad s~| the mean central-difference gradient magnitude over the voxels
// next to the isosurface; then the voxels next to the isosurface set to their subcell distance,
// the distance swept from them to the whole grid (sdf/fast_sweep.h, first order) and polished
// by redistancing until the voxels within 3 of the surface settle (level_set.cpp says why).
// `isovalue` is in the volume's data units. A volume that never crosses the isovalue gives the
// scaled difference, all of one sign.
//
// s~ is s smoothed by a separable Gaussian of standard deviation `presmoothSigma` voxels along
// each axis (in that axis's own voxels; edge voxels repeat at the faces; <= 0: no smoothing).
// Why: the zero set of the trilinear interpolant of a field whose edge is about as sharp as the
// grid (a piecewise-constant phantom, a thin wall, bone or skin in CT) is terraced at voxel
// scale, and the SDF inherits the terraces, so shaded normals ripple in rings and contour-line
// dots ("fingerprints"). On a sphere phantom with a 2-voxel smoothstep edge the normal at the
// zero set (central differences over +-0.5 voxel) is off by 2.4 deg mean / 8 deg max without
// smoothing, 1.0 / 3.5 deg at sigma 0.85.
// sigma 0.85 removes most of the aliasing (the Gaussian's response at the grid's Nyquist
// frequency is exp(-pi^2 sigma^2 / 2) ~ 3 %) while moving the zero set of smooth data by
// ~sigma^2 / (2 R) (0.035 voxel on a sphere of 22 voxels) and that of a 2-voxel wall by < 0.2
// voxel. Larger sigmas erase thin walls: at 1.2 the built-in Shepp-Logan skull (a wall of 2-3
// voxels at 128^3) already opens.
Field3D sdfFromIsovalue(const Volume& volume, double isovalue, bool insideHigh,
                        const LevelSetSettings& s, Precision p, MemoryLedger* ledger,
                        float presmoothSigma = kIsoPresmoothSigma);

// Eq. 26: |phi0| - d, d >= 0 in world units (BadInput/Usage error for d < 0 or NaN).
// d = 0 is an infinitely thin shell: the field is >= 0 everywhere and touches 0 only on the
// surface, so nothing is inside. A d larger than the object fills it and grows it by d.
Field3D thinShell(const Field3D& filled, float d, Precision p, MemoryLedger* ledger);

}  // namespace visopt
