// Image-difference metrics beside visopt::psnr (image.h): SSIM and LDR-ꟻLIP, the metric paper 000
// uses to compare fp16 and fp32 renderings. All take linear-RGB images as readPng returns them and
// evaluate them as a display shows them (each channel clamped to [0, 1], sRGB-encoded).
#pragma once

#include <vector>

#include "visopt/image.h"

namespace visopt {

// Mean structural similarity (Wang, Bovik, Sheikh, Simoncelli 2004) on the luma of the
// sRGB-encoded images (Rec. 709 weights on the encoded channels): an 11x11 Gaussian window
// (sigma 1.5), K1 = 0.01, K2 = 0.03, dynamic range 1, averaged over the window positions that lie
// wholly inside the image. 1 means identical. Error(Usage) when the sizes differ or an image is
// smaller than the window (ssimApplies says which).
double ssim(const Image& a, const Image& b);
bool ssimApplies(const Image& a);

// Pixels per degree of visual angle for an observer `distanceM` metres from a monitor `widthM`
// metres wide with `columns` pixels across: distance * columns / width * pi / 180.
double pixelsPerDegree(double distanceM, double widthM, double columns);
// ꟻLIP's default observer: 0.7 m from a 0.7 m wide monitor 3840 pixels across (67.02 px/deg).
double flipDefaultPixelsPerDegree();

// The per-pixel LDR-ꟻLIP error of `test` against `reference` (Andersson, Nilsson, Akenine-Möller,
// Oskarsson, Åström, Fairchild, HPG 2020), each in [0, 1], 0 where the two are indistinguishable,
// and its statistics.
struct FlipResult {
  int width = 0, height = 0;
  std::vector<float> error;  // row-major, row 0 at the top
  double mean = 0.0;         // summed in double precision
  double p95 = 0.0;          // the plain 95th percentile (nearest rank)
  // The reference tool's weighted median: the first error, in ascending order, at which the
  // running sum of errors passes half of their total (0 for identical images).
  double weightedMedian = 0.0;
  double max = 0.0;
};
// Error(Usage) when the sizes differ, an image is empty or pixelsPerDegree is not positive and
// finite. NaN pixels count as black, as writePng writes them.
FlipResult flip(const Image& reference, const Image& test,
                double pixelsPerDegree = flipDefaultPixelsPerDegree());

}  // namespace visopt
