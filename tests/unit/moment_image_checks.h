// The comparison the moment-image tests share: an image made another way (from slabs, on MPI
// ranks) against generateMomentImage's. Counts and bounds are exact (integers and min/max), the
// moments agree to 1e-6 (sums in a different order).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "visopt/moment_image.h"

namespace visopt::testing {

inline void expectSameMomentImage(const MomentImage& a, const MomentImage& b,
                                  const std::string& what) {
  ASSERT_EQ(a.width, b.width) << what;
  ASSERT_EQ(a.height, b.height) << what;
  EXPECT_EQ(a.camera, b.camera) << what;
  EXPECT_EQ(a.valueMin, b.valueMin) << what;
  EXPECT_EQ(a.valueMax, b.valueMax) << what;
  ASSERT_EQ(a.pixelCount(), b.pixelCount()) << what;
  size_t countsDiffer = 0;
  for (size_t p = 0; p < a.pixelCount(); ++p) countsDiffer += a.counts[p] != b.counts[p];
  ASSERT_EQ(countsDiffer, 0u) << what << ": pixels whose moment counts differ";
  EXPECT_EQ(a.lower, b.lower) << what << ": the bounds are min and max, exact";
  EXPECT_EQ(a.upper, b.upper) << what;
  ASSERT_EQ(a.moments.size(), b.moments.size()) << what;
  double worst = 0.0;
  for (size_t i = 0; i < a.moments.size(); ++i)
    worst = std::max(worst, double(std::abs(a.moments[i] - b.moments[i])));
  EXPECT_LE(worst, 1e-6) << what;
}

}  // namespace visopt::testing
