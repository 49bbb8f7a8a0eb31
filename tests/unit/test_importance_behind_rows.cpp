// ghat (Eq. 19) on the CPU backend (host/importance_behind_rows.h: rows of voxels, the frustum
// maxima sampled 16 at a time) against the per-voxel ImportanceBehind that CUDA runs
// (kernels/importance_behind.h): the same ghat to float round-off for fp32 and fp16 maxima and
// ghat, with and without the light half, under a lens and a screen mask, and with the eye inside
// the grid (voxels behind it and beside the frustum). The grid's rows (29 voxels) are not a whole
// number of chunks.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/frustum_field.h"
#include "core/frustum_map.h"
#include "host/importance_behind_rows.h"
#include "kernels/importance_behind.h"
#include "visopt/camera.h"
#include "visopt/field.h"
#include "visopt/frustum.h"

using namespace visopt;

namespace {

enum class Weights { None, Lens, Mask };

struct Case {
  Precision precision;
  bool light;
  Weights weights;
  bool eyeInside;
  std::string name() const {
    return std::string(precision == Precision::FP16 ? "fp16" : "fp32") + (light ? "_light" : "") +
           (weights == Weights::Lens   ? "_lens"
            : weights == Weights::Mask ? "_mask"
                                       : "") +
           (eyeInside ? "_eyeInside" : "");
  }
};

struct Problem {
  GridSpec grid;
  FrustumGrid view, light;
  Field3D viewMax, lightMax, mask;
};

Field3D randomFrustumField(const char* name, const FrustumGrid& f, Precision p, std::mt19937& rng) {
  GridSpec g;
  g.dims = frustumStorageDims(f.dims);
  Field3D out(name, g, p);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (size_t v = 0; v < out.size(); ++v) out.set(v, u(rng));
  return out;
}

Problem makeProblem(const Case& c) {
  Problem p;
  p.grid.dims = glm::ivec3(29, 13, 11);
  p.grid.spacing = glm::vec3(0.05f, 0.07f, 0.06f);
  p.grid.origin = -0.5f * glm::vec3(p.grid.dims - 1) * p.grid.spacing;
  const Bounds bounds = p.grid.worldBounds();
  Camera cam;
  cam.eye = c.eyeInside ? glm::vec3(0.1f, 0.05f, 0.02f) : glm::vec3(0.5f, -2.f, 0.8f);
  cam.target = glm::vec3(0.f);
  p.view = FrustumGrid::forCamera(cam, 24, 18, bounds, 0, p.grid.minSpacing());
  PointLight light;
  light.position = glm::vec3(1.1f, 0.9f, 1.4f);
  p.light = FrustumGrid::forLight(light, bounds, glm::ivec3(19, 19, 0), p.grid.minSpacing());
  std::mt19937 rng(5);
  p.viewMax = randomFrustumField("view max", p.view, c.precision, rng);
  p.lightMax = randomFrustumField("light max", p.light, c.precision, rng);
  if (c.weights == Weights::Mask) {
    GridSpec mg;
    mg.dims = glm::ivec3(7, 5, 1);
    p.mask = Field3D("screen mask", mg, Precision::FP32);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (size_t v = 0; v < p.mask.size(); ++v) p.mask.set(v, u(rng));
  }
  return p;
}

ImportanceBehind kernelOf(const Problem& p, const Case& c, Field3D& ghat) {
  ImportanceBehind k;
  k.volume = GridMap(p.grid);
  k.ghat = FieldView(ghat);
  k.view = FrustumMap(p.view);
  k.light = FrustumMap(p.light);
  k.viewMax = FrustumFieldView(p.viewMax, p.view.dims);
  if (c.light) k.lightMax = FrustumFieldView(p.lightMax, p.light.dims);
  if (c.weights == Weights::Lens) {
    k.weights.lensCentre = glm::vec2(0.4f, 0.6f);
    k.weights.lensRadius = 0.35f;
    k.weights.lensStrength = 0.f;
  } else if (c.weights == Weights::Mask) {
    k.weights.mask = FieldView(p.mask);
  }
  return k;
}

class ImportanceBehindRows : public ::testing::TestWithParam<Case> {};

TEST_P(ImportanceBehindRows, MatchesThePerVoxelKernel) {
  const Case c = GetParam();
  const Problem p = makeProblem(c);
  Field3D ref("ghat", p.grid, c.precision), rows("ghat", p.grid, c.precision);
  ref.fill(-1.f);
  rows.fill(-1.f);
  const ImportanceBehind refKernel = kernelOf(p, c, ref);
  const glm::ivec3 n = p.grid.dims;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) refKernel(i, j, k);
  importanceBehindOnHost("test importance behind", kernelOf(p, c, rows));

  // The frustum mapping may contract into FMAs differently in the lanes (~1e-6 of a frustum
  // coordinate); the random maxima change by up to 1 between cells. fp16 stores ghat with 11
  // significant bits.
  const float tol = c.precision == Precision::FP16 ? 2e-3f : 2e-5f;
  size_t inside = 0, zero = 0;
  for (size_t v = 0; v < ref.size(); ++v) {
    ASSERT_NEAR(rows.get(v), ref.get(v), tol) << "voxel " << v;
    inside += ref.get(v) > 0.f;
    zero += ref.get(v) == 0.f;
  }
  EXPECT_GT(inside, ref.size() / 20);  // the frusta cover part of the grid at least
  if (c.eyeInside && !c.light) {
    EXPECT_GT(zero, 0u);  // voxels behind the eye or beside the view frustum
  }
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (Precision p : {Precision::FP32, Precision::FP16})
    for (bool light : {false, true})
      for (Weights w : {Weights::None, Weights::Lens, Weights::Mask})
        out.push_back({p, light, w, false});
  out.push_back({Precision::FP32, true, Weights::Lens, true});
  out.push_back({Precision::FP16, false, Weights::None, true});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Cases, ImportanceBehindRows, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name(); });

}  // namespace
