// fp16 against fp32 storage: images of the default scene, before and after optimisation, differ
// by a small stated amount, and the memory ledger shows fp16 storage at most ~60 % of fp32.
#include <gtest/gtest.h>

#include "visopt/engine.h"

using namespace visopt;

namespace {

struct PrecisionRun {
  Image before, after;
  size_t bytes = 0;
};

PrecisionRun run(Precision p) {
  Engine e(p);
  e.loadBuiltinScene("shepp-logan", 64);
  RenderSettings rs;
  rs.width = rs.height = 96;
  e.setViewportSize(rs.width, rs.height);
  PrecisionRun r;
  r.before = e.render(rs);
  ExtinctionSettings s;
  s.levels = 2;
  s.maxIterationsPerLevel = 25;
  s.r = 10.f;  // light grids too, so every kind of field is in the ledger
  e.setExtinctionSettings(s);
  e.optimize();
  r.after = e.render(rs);
  r.bytes = e.ledger().totalBytes();
  return r;
}

}  // namespace

TEST(Precision, Fp16MatchesFp32WithinStatedPsnrAndHalvesMemory) {
  const PrecisionRun a = run(Precision::FP32), b = run(Precision::FP16);
  const double before = psnr(a.before, b.before), after = psnr(a.after, b.after);
  std::printf(
      "fp16 vs fp32 PSNR: %.1f dB before, %.1f dB after optimisation; memory %zu vs %zu bytes "
      "(%.0f %%)\n",
      before, after, b.bytes, a.bytes, 100.0 * double(b.bytes) / double(a.bytes));
  EXPECT_GT(before, 40.0) << "plain rendering: fp16 storage of normalised scalars and T_L";
  EXPECT_GT(after, 30.0) << "after 50 optimiser steps with fp16 moments and mu";
  EXPECT_LE(double(b.bytes), 0.6 * double(a.bytes));
}
