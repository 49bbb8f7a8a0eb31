// CPU-vs-CUDA parity: the same kernels (light transmittance, ray marching) on both backends give
// the same image. Skipped — reported as skipped, not passed — when no CUDA device answers.
#include <gtest/gtest.h>

#include "exec/parallel.h"
#include "render_fixtures.h"
#include "visopt/engine.h"
#include "visopt/exec.h"

using namespace visopt;
using namespace visopt::testing;

TEST(BackendParity, RenderMatchesBetweenCpuAndCuda) {
  if (!cudaCompiledIn()) GTEST_SKIP() << "built without the CUDA backend";
  if (activeBackend() != Backend::CUDA) GTEST_SKIP() << "no CUDA device answers on this machine";
  Engine engine;
  engine.setVolume(homogeneousCube(24));
  engine.setTransferFunction(constantTransferFunction(0.15f, glm::vec3(0.8f, 0.5f, 0.3f)));
  engine.orbitCamera(30.f, 20.f, 2.5f);
  RenderSettings s;
  s.width = s.height = 64;
  Image cuda, cpu;
  {
    exec::ScopedBackend on(Backend::CUDA);
    cuda = engine.render(s);
  }
  {
    exec::ScopedBackend on(Backend::CPU);
    engine.setLight(engine.light());  // recompute T_L on the CPU too
    cpu = engine.render(s);
  }
  ASSERT_EQ(cuda.pixels.size(), cpu.pixels.size());
  float maxDiff = 0.f;
  for (size_t i = 0; i < cpu.pixels.size(); ++i)
    maxDiff = std::max(maxDiff, glm::length(cpu.pixels[i] - cuda.pixels[i]));
  EXPECT_LT(maxDiff, 1e-3f);
}
