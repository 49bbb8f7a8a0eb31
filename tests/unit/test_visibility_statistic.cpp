// The visibility-through-occluders statistic (IterationStats::visibilityViewOccluders):
// sum g mu T / sum g mu T_imp, against closed forms on the occluder test scene. It is 1 when
// nothing unimportant hides the important structure, whatever the structure hides of itself,
// and e^-tau behind an unimportant slab of optical depth tau.
#include <cmath>

#include <gtest/gtest.h>

#include "occluder_scene.h"
#include "visopt/engine.h"

using namespace visopt;
using namespace visopt::testing;

namespace {

// The statistic at mu = mu_bar: the first iteration's scan happens before its step.
double occluderVisibilityAtStart(const OccluderScene& scene, Precision precision) {
  Engine e(precision);
  loadOccluderScene(e, scene);
  ExtinctionSettings s;
  s.levels = 1;
  s.maxIterationsPerLevel = 1;
  s.frustumScale = 1.f;
  e.setExtinctionSettings(s);
  const auto stats = e.optimize();
  EXPECT_FALSE(stats.empty());
  return stats.empty() ? -1.0 : stats.front().visibilityViewOccluders;
}

OccluderScene withoutSlab(OccluderScene s) {
  s.slabY0 = s.slabY1 = 1e4f;  // outside the grid
  return s;
}

}  // namespace

TEST(VisibilityStatistic, NothingInTheWayIsOne) {
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    // A thin disc, and a thick sphere that shades its own back (mu_bar of the blob values).
    OccluderScene disc = withoutSlab({});
    EXPECT_NEAR(occluderVisibilityAtStart(disc, p), 1.0, 1e-5);
    OccluderScene sphere = withoutSlab({});
    sphere.blobHalfThickness = sphere.blobRadius;
    EXPECT_NEAR(occluderVisibilityAtStart(sphere, p), 1.0, 1e-5)
        << "the sphere's own front is not an occluder, nor is its partial-volume rim";
  }
}

TEST(VisibilityStatistic, BehindAnUnimportantSlabItIsItsTransmittance) {
  // The slab's voxels (centres -11.5 .. -2.5, 10 planes at mu_max = 0.3 per unit) integrate to
  // an optical depth of 3 along y; every ray through the disc crosses it (within 3.2 degrees of
  // the axis: a path 0.16 % longer).
  const double expected = std::exp(-3.0);
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    EXPECT_NEAR(occluderVisibilityAtStart({}, p), expected, 0.03 * expected);
    OccluderScene sphere;
    sphere.blobHalfThickness = sphere.blobRadius;
    EXPECT_NEAR(occluderVisibilityAtStart(sphere, p), expected, 0.03 * expected)
        << "self-shading cancels: only the slab counts";
  }
}
