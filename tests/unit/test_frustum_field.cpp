// Frustum fields in tiles of adjacent rays (core/frustum_field.h): every cell has its own slot,
// and sampling is trilinear interpolation, clamped at the borders, on either precision.
#include <set>

#include <gtest/gtest.h>

#include "core/frustum_field.h"
#include "visopt/field.h"

using namespace visopt;

namespace {

Field3D storageFor(glm::ivec3 dims, Precision p) {
  GridSpec g;
  g.dims = frustumStorageDims(dims);
  return Field3D("frustum field", g, p);
}

}  // namespace

TEST(FrustumField, EveryCellHasItsOwnSlot) {
  for (glm::ivec3 dims : {glm::ivec3(1, 1, 1), glm::ivec3(16, 3, 5), glm::ivec3(37, 4, 9)}) {
    const Field3D f = storageFor(dims, Precision::FP32);
    const FrustumFieldView v(f, dims);
    std::set<size_t> seen;
    for (int k = 0; k < dims.z; ++k)
      for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) {
          const size_t c = v.index(i, j, k);
          ASSERT_LT(c, f.size());
          ASSERT_TRUE(seen.insert(c).second) << i << " " << j << " " << k;
        }
    // Padding only rounds the rays along x up to whole tiles.
    EXPECT_EQ(f.size(), size_t((dims.x + kTileRays - 1) / kTileRays * kTileRays) * dims.y * dims.z);
  }
}

// Trilinear interpolation reproduces an affine function exactly inside the grid and clamps
// outside it.
TEST(FrustumField, SamplingIsTrilinearAndClamped) {
  const glm::ivec3 dims(21, 6, 11);
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    Field3D f = storageFor(dims, p);
    const FrustumFieldView v(f, dims);
    auto affine = [](glm::vec3 x) { return 0.25f * x.x - 0.5f * x.y + 0.125f * x.z + 1.f; };
    for (int k = 0; k < dims.z; ++k)
      for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) v.store(v.index(i, j, k), affine(glm::vec3(i, j, k)));
    const float tol = p == Precision::FP16 ? 4e-3f : 1e-5f;
    for (glm::vec3 x :
         {glm::vec3(0.f), glm::vec3(15.5f, 2.25f, 7.75f), glm::vec3(16.2f, 4.9f, 0.3f),
          glm::vec3(19.9f, 5.f, 10.f), glm::vec3(3.3f, 0.7f, 9.5f)})
      EXPECT_NEAR(v.sample(x), affine(x), tol) << x.x << " " << x.y << " " << x.z;
    EXPECT_NEAR(v.sample(glm::vec3(-3.f, 2.f, 4.f)), affine(glm::vec3(0.f, 2.f, 4.f)), tol);
    EXPECT_NEAR(v.sample(glm::vec3(25.f, 9.f, 14.f)), affine(glm::vec3(20.f, 5.f, 10.f)), tol);
  }
}
