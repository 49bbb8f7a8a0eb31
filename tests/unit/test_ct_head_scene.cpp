// builtin:ct-head, the small CT-like head that reproduces why real head scans stayed hidden
// (a skin isosurface around thick soft tissue and a thick skull marked important): with the
// default settings the skull comes into view; with the settings the diagnosis blamed (the skin
// filled, a fixed four level-set substeps per iteration) it stays mostly hidden, as the
// Cranium CT did.
#include <gtest/gtest.h>

#include "visopt/engine.h"

using namespace visopt;

namespace {

struct Outcome {
  double before = 0.0, after = 0.0;
};

Outcome runHead(Precision precision, bool diagnosedSettings) {
  Engine e(precision);
  e.loadBuiltinScene("ct-head", 64);
  e.setViewportSize(128, 128);
  if (diagnosedSettings) {
    ContextSurfaceSpec skin = e.contextSurfaces().at(0);
    skin.filled = true;
    skin.shell = 0.f;
    e.clearContextSurfaces();
    e.addContextSurface(skin);
    LevelSetSettings ls = e.levelSetSettings();
    ls.reach = 0.f;  // substeps alone, as before
    e.setLevelSetSettings(ls);
  }
  const auto stats = e.optimize();
  EXPECT_FALSE(stats.empty());
  if (stats.empty()) return {};
  return {stats.front().visibilityViewOccluders, stats.back().visibilityViewOccluders};
}

}  // namespace

TEST(CtHeadScene, TheSkullComesIntoViewWithTheDefaults) {
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    const Outcome o = runHead(p, false);
    EXPECT_LT(o.before, 0.1) << "the skin hides the skull at first";
    EXPECT_GT(o.after, 0.8) << (p == Precision::FP16 ? "fp16" : "fp32");
  }
}

TEST(CtHeadScene, AFilledSkinWithFixedSubstepsStaysMostlyClosed) {
  const Outcome o = runHead(Precision::FP32, true);
  EXPECT_LT(o.before, 0.1);
  EXPECT_LT(o.after, 0.6) << "the scene no longer shows the failure it was built to reproduce";
}
