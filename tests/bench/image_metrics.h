// Image error metrics for the speed/accuracy study: SSIM on luminance (PSNR is visopt::psnr).
#pragma once

#include <vector>

#include "visopt/image.h"

namespace visopt::bench {

// Per-pixel luma of the sRGB-encoded image (Rec. 709 weights on the encoded channels, each
// clamped to [0, 1] first), row-major: the values a display shows, as PSNR uses them.
std::vector<float> srgbLuma(const Image& image);

// Mean structural similarity (Wang, Bovik, Sheikh, Simoncelli 2004) of two equally sized images
// on srgbLuma: an 11x11 Gaussian window (sigma 1.5), K1 = 0.01, K2 = 0.03, dynamic range L = 1,
// averaged over the window positions that lie wholly inside the image. 1 means identical.
// Throws std::invalid_argument when the sizes differ or the image is smaller than the window.
double ssim(const Image& a, const Image& b);

}  // namespace visopt::bench
