// Moment images (Rapp, Peters, Dachsbacher 2022): per pixel of a fixed view, the bounded
// trigonometric moments of the volume's density along the pixel's ray (§3.2), so that any transfer
// function can be applied and changed later without the volume (§3.3). The density is the
// volume's normalised scalar in [0, 1]; the ray's interval inside the volume maps linearly to
// phase [-pi, 0]. Each pixel keeps the bounds of Eq. 5 and as many moments as §3.5's error
// threshold asks for.
//
// This is the uncompressed form: the moments are stored as 32-bit floats (§3.6's coding and
// quantization are not applied yet).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "visopt/camera.h"
#include "visopt/field.h"
#include "visopt/grid.h"
#include "visopt/image.h"
#include "visopt/transfer_function.h"
#include "visopt/volume.h"

namespace visopt {

// Moments 0..m are generated with m at most this (the paper: 100).
inline constexpr int kMaxMomentOrder = 127;

struct MomentImageSettings {
  int width = 512, height = 512;
  int moments = 100;             // m: the order generated (moments 0..m), 0..kMaxMomentOrder
  float errorThreshold = 0.01f;  // §3.5: each pixel keeps the fewest moments within this rRMSE
                                 // of all m + 1; 0 keeps all of them
  float boundsMargin = 0.005f;   // epsilon of §3.2: the bounds are [min - eps, max + eps]
  float stepVoxels = 0.5f;       // ray-march step, in units of the smallest voxel spacing
  // §4.1: when in (0, 1), a second march stores per pixel this quantile of the reconstruction's
  // error along the ray (|bounded MESE - volume| in normalised density); 0: none.
  float uncertaintyQuantile = 0.f;
};

// Throws Error(Usage) naming the setting when one is out of range.
void checkMomentImageSettings(const MomentImageSettings& s);

struct MomentImage {
  int width = 0, height = 0;
  int order = 0;  // m of the generation
  Camera camera;
  GridSpec grid;                          // the volume's geometry: each ray's [t0, t1] follows
  double valueMin = 0.0, valueMax = 1.0;  // data units of the normalised density 0 and 1
  float boundsMargin = 0.005f, errorThreshold = 0.01f, stepVoxels = 0.5f;
  // Per pixel (row 0 at the top): how many moments are stored (0: the ray misses the volume)
  // and the bounds [lower, upper] of Eq. 5.
  std::vector<uint8_t> counts;
  std::vector<float> lower, upper;
  // The rescaled moments c^t of Eq. 5 of every pixel, pixel after pixel.
  std::vector<float> moments;
  // §4.1, when generated: per pixel the uncertaintyQuantile of the error along the ray.
  float uncertaintyQuantile = 0.f;
  std::vector<float> uncertainty;

  size_t pixelCount() const { return size_t(width) * size_t(height); }
  // Start of each pixel's moments in `moments` (pixelCount() + 1 entries).
  std::vector<uint64_t> offsets() const;
};

struct MomentGenerationStats {
  double marchMs = 0.0, countMs = 0.0;  // ray marching with moment accumulation; §3.5's counts
  int64_t samples = 0;                  // density samples taken
  double meanMoments = 0.0;             // stored moments per pixel hit by the volume
  double uncertaintyMs = 0.0;           // §4.1's second march, when asked for
};

MomentImage generateMomentImage(const Volume& volume, const Camera& camera,
                                const MomentImageSettings& settings,
                                MomentGenerationStats* stats = nullptr);

// Distributed generation (§3.2's moments are integrals along the ray: those of disjoint pieces
// add, and Eq. 5's rescaling is linear in them). The grid is cut into slabs along z; a slab owns
// the ray samples whose z lies in its slices and adds the raw moments of the piece from its first
// sample to the one after its last, and the min and max of its samples. The partials of all slabs
// summed (min and max for the bounds), in any order and on any process, and finished give
// generateMomentImage's image up to the order of the sums (double precision). The §4.1
// uncertainty, a second march over each whole ray, is not computed this way.
struct MomentPartials {
  int width = 0, height = 0, order = 0;
  std::vector<double> moments;  // per pixel, order + 1 raw moments of the pieces added
  std::vector<float> lower,
      upper;  // per pixel, min and max of the samples added (none: lower > upper)
};
MomentPartials emptyMomentPartials(const MomentImageSettings& settings);
// Slices beyond its own on each side that a slab must hold (the piece's last sample and the
// trilinear stencil): ceil(stepVoxels) + 1.
int momentSlabHalo(const MomentImageSettings& settings);
// Adds the slab owning slices [ownedBegin, ownedEnd) of `grid` (the whole volume's geometry),
// read from `slab`: the normalised density of slices [slabFirst, slabFirst + its dims.z) with
// the grid's x and y dims, holding the owned slices and momentSlabHalo more each side (as far as
// the grid has them). Throws Error(Usage) otherwise. marchMs, when given, is added the time.
void addMomentSlab(MomentPartials& partials, const Field3D& slab, int slabFirst, int ownedBegin,
                   int ownedEnd, const GridSpec& grid, const Camera& camera,
                   const MomentImageSettings& settings, double* marchMs = nullptr);
// into += other (sums; min and max of the bounds): what a reduction across processes does.
void mergeMomentPartials(MomentPartials& into, const MomentPartials& other);
// Eq. 5 and §3.5's counts for a run of pixels from their merged partials (order + 1 moments and
// the bounds of each), so that processes can finish a share of the pixels each; momentImageOf
// puts the runs of all pixels, in order, together. countMs, when given, is added the count's time.
struct MomentPixels {
  std::vector<uint8_t> counts;
  std::vector<float> lower, upper, moments;  // as in MomentImage
};
MomentPixels finishMomentPixels(std::span<const double> moments, std::span<const float> lower,
                                std::span<const float> upper, const MomentImageSettings& settings,
                                double* countMs = nullptr);
MomentImage momentImageOf(MomentPixels pixels, const GridSpec& grid, const Camera& camera,
                          const MomentImageSettings& settings, double valueMin, double valueMax);
// The image of every slab's partials merged: Eq. 5 and §3.5's counts, as generateMomentImage.
// valueMin/valueMax: the data units of the normalised density 0 and 1 (the whole volume's).
MomentImage finishMomentImage(const MomentPartials& total, const GridSpec& grid,
                              const Camera& camera, const MomentImageSettings& settings,
                              double valueMin, double valueMax,
                              MomentGenerationStats* stats = nullptr);

enum class MomentReconstruction { BoundedMese, Fourier };
const char* toString(MomentReconstruction r);

struct MomentRenderSettings {
  MomentReconstruction reconstruction = MomentReconstruction::BoundedMese;
  float stepVoxels = 0.5f;  // ray-march step, in units of the smallest voxel spacing
  // Pre-integrated transfer function (Engel et al. 2001, in its cumulative-table form: the
  // extinction and the emitted colour integrated over the segment's linear density ramp, the
  // self-attenuation within a segment neglected); false samples each segment at its midpoint.
  bool preintegrate = true;
  // Evaluate each ray's density one sample after the other and each pixel's multipliers one
  // pixel after the other (the reference); false evaluates 16 samples, and on the CPU the
  // multipliers of 8 pixels, side by side (the same arithmetic per sample and pixel, SIMD-wide).
  bool perSampleReference = false;
};

// Emission-absorption rendering of a moment image with a transfer function (in the volume's
// data units): each pixel's density is reconstructed along its ray, mapped back through Eq. 5,
// and composited front to back with the albedo as emitted colour; background black.
Image renderMomentImage(const MomentImage& image, const TransferFunction& tf,
                        const MomentRenderSettings& settings);
// The same rendering from the volume itself, the reference a moment image is compared with.
Image renderVolumeEmissionAbsorption(const Volume& volume, const Camera& camera, int width,
                                     int height, const TransferFunction& tf,
                                     const MomentRenderSettings& settings);

// §4.1's uncertainty as a heat map (visopt/colormap.h's magma from 0 to `maxError`; 0 takes the
// image's largest value); black where the ray misses the volume. Throws Error(Usage) when the
// image holds no uncertainty.
Image renderMomentUncertainty(const MomentImage& image, float maxError = 0.f);
// The error at the top of that heat map: maxError when positive, else the image's largest.
float uncertaintyHeatMapTop(const MomentImage& image, float maxError = 0.f);

// The normalised density along pixel (x, y)'s ray at `samples` points from t0 to t1: from the
// moment image, and from the volume (the ground truth of §5.2's sample PSNR).
std::vector<float> reconstructRay(const MomentImage& image, int x, int y, int samples,
                                  MomentReconstruction r);
std::vector<float> sampleRay(const Volume& volume, const MomentImage& image, int x, int y,
                             int samples);

// The .vmi file, version 1: little-endian, a header block and the counts, bounds and moments
// blocks (and the uncertainty block when there is one), each with its length and CRC-32. Writing is
// atomic. Reading refuses, naming the file, a wrong magic or version, a truncated file, a block
// whose checksum or length is wrong, counts above the order, bounds that are not finite or not
// increasing, and a header claiming more pixels or moments than the file holds.
void writeMomentImage(const MomentImage& image, const std::string& path);
MomentImage readMomentImage(const std::string& path);

}  // namespace visopt
