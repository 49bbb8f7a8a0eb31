// The host steps that build a base SDF from an isovalue (optimize/level_set.h sdfFromIsovalue):
// fast sweeping from a band (sdf/fast_sweep.h), against its serial reference bit for bit and
// against exact distances where first-order Godunov is exact, and the separable Gaussian
// pre-smoothing (sdf/gaussian_smoothing.h) against its defining sums.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/field_view.h"
#include "sdf/fast_sweep.h"
#include "sdf/gaussian_smoothing.h"
#include "visopt/field.h"

namespace visopt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct Band {
  std::vector<float> d;
  std::vector<uint8_t> fixed;
};

// The voxels next to the zero set of `f` (a face neighbour of the other sign) fixed at |f|, the
// rest at +infinity, as sdfFromIsovalue hands them to the sweep.
template <class F>
Band bandOf(glm::ivec3 n, glm::vec3 h, F f) {
  Band b;
  const size_t count = size_t(n.x) * n.y * n.z;
  b.d.assign(count, kInf);
  b.fixed.assign(count, 0);
  auto at = [&](int i, int j, int k) {
    return f(glm::vec3(float(i) * h.x, float(j) * h.y, float(k) * h.z));
  };
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const float c = at(i, j, k);
        bool edge = false;
        const int off[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
        for (const auto& o : off) {
          const int a = i + o[0], bb = j + o[1], c2 = k + o[2];
          if (a < 0 || bb < 0 || c2 < 0 || a >= n.x || bb >= n.y || c2 >= n.z) continue;
          edge = edge || c * at(a, bb, c2) <= 0.f;
        }
        const size_t v = size_t(i + n.x * (j + n.y * k));
        if (edge) {
          b.fixed[v] = 1;
          b.d[v] = std::fabs(c);
        }
      }
  return b;
}

void expectSweepsAgree(glm::ivec3 n, glm::vec3 h, Band b) {
  Band serial = b;
  fastSweep(b.d, b.fixed, n, h, 1e-3f * std::min({h.x, h.y, h.z}), 8);
  fastSweepSerial(serial.d, serial.fixed, n, h, 1e-3f * std::min({h.x, h.y, h.z}), 8);
  size_t differ = 0, infinite = 0;
  for (size_t v = 0; v < b.d.size(); ++v) {
    differ += b.d[v] != serial.d[v];  // bit for bit (no NaN occurs)
    infinite += std::isinf(b.d[v]);
  }
  EXPECT_EQ(differ, 0u) << n.x << "x" << n.y << "x" << n.z;
  EXPECT_EQ(infinite, 0u);
}

// The parallel sweep (anti-diagonals of rows, voxels next to a change only) gives exactly the
// serial sweep's field: nested and touching shapes whose distances need several rounds,
// anisotropic spacing, shapes cut by the grid's faces, a grid one voxel thick, a single row.
TEST(FastSweep, TheParallelSweepEqualsTheSerialOneBitForBit) {
  auto spheres = [](glm::vec3 x) {
    const float a = glm::length(x - glm::vec3(6.f, 7.f, 5.f)) - 4.f;
    const float b = glm::length(x - glm::vec3(13.f, 9.f, 6.f)) - 3.5f;
    return std::min(a, b);
  };
  expectSweepsAgree({40, 36, 24}, {0.5f, 0.5f, 0.5f},
                    bandOf({40, 36, 24}, {0.5f, 0.5f, 0.5f}, spheres));
  expectSweepsAgree({33, 27, 19}, {0.6f, 0.45f, 0.9f},
                    bandOf({33, 27, 19}, {0.6f, 0.45f, 0.9f}, spheres));
  // A shell (concave inside), cut by the grid's faces.
  auto shell = [](glm::vec3 x) {
    return std::fabs(glm::length(x - glm::vec3(2.f, 3.f, 1.f)) - 6.f) - 1.f;
  };
  expectSweepsAgree({30, 26, 18}, {0.5f, 0.5f, 0.5f},
                    bandOf({30, 26, 18}, {0.5f, 0.5f, 0.5f}, shell));
  // Thin grids: the slab's own plane cuts the spheres' centres.
  auto inSlab = [&](glm::vec3 offset) { return [=](glm::vec3 x) { return spheres(x + offset); }; };
  expectSweepsAgree({41, 1, 23}, {0.5f, 1.f, 0.5f},
                    bandOf({41, 1, 23}, {0.5f, 1.f, 0.5f}, inSlab({0.f, 7.f, 0.f})));
  expectSweepsAgree({64, 1, 1}, {0.25f, 1.f, 1.f},
                    bandOf({64, 1, 1}, {0.25f, 1.f, 1.f}, inSlab({0.f, 7.f, 5.f})));
  expectSweepsAgree({1, 50, 37}, {1.f, 0.5f, 0.5f},
                    bandOf({1, 50, 37}, {1.f, 0.5f, 0.5f}, inSlab({6.f, 0.f, 0.f})));
}

// First-order Godunov is exact for a plane along a grid axis: every voxel gets its distance to
// it, on both sides and with anisotropic spacing.
TEST(FastSweep, AnAxisAlignedPlaneGetsItsExactDistance) {
  const glm::ivec3 n(21, 17, 30);
  const glm::vec3 h(0.7f, 0.4f, 0.3f);
  const float plane = 4.05f;  // z of the plane, between two voxel layers
  Band b = bandOf(n, h, [&](glm::vec3 x) { return x.z - plane; });
  fastSweep(b.d, b.fixed, n, h, 1e-4f, 8);
  float worst = 0.f;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const float exact = std::fabs(float(k) * h.z - plane);
        worst = std::max(worst, std::fabs(b.d[size_t(i + n.x * (j + n.y * k))] - exact));
      }
  EXPECT_LT(worst, 1e-5f);
}

// Elsewhere first order: a sphere's distance, inside and out, within a voxel.
TEST(FastSweep, ASphereIsWithinAVoxelOfItsDistance) {
  const glm::ivec3 n(48, 48, 48);
  const glm::vec3 h(0.5f);
  const glm::vec3 c(11.7f, 12.1f, 11.9f);
  const float r = 5.f;
  auto f = [&](glm::vec3 x) { return glm::length(x - c) - r; };
  Band b = bandOf(n, h, f);
  fastSweep(b.d, b.fixed, n, h, 1e-4f, 8);
  float worst = 0.f;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const float exact = std::fabs(f(glm::vec3(i, j, k) * h));
        const float got = b.d[size_t(i + n.x * (j + n.y * k))];
        worst = std::max(worst, std::fabs(got - exact) / h.x);
      }
  EXPECT_LT(worst, 1.f);
}

// ---- the Gaussian ---------------------------------------------------------------------------

Field3D fieldOf(glm::ivec3 n, Precision p, float (*f)(int, int, int)) {
  GridSpec g;
  g.dims = n;
  Field3D out("test", g, p, nullptr);
  const FieldView view(out);
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) view.store(size_t(i + n.x * (j + n.y * k)), f(i, j, k));
  return out;
}

// The normalised, truncated weights the smoothing documents.
std::vector<double> weights(float sigma) {
  const int r = std::max(1, int(std::ceil(3.f * sigma)));
  std::vector<double> w;
  double total = 0.0;
  for (int o = -r; o <= r; ++o) w.push_back(std::exp(-0.5 * o * o / (double(sigma) * sigma)));
  for (double x : w) total += x;
  for (double& x : w) x /= total;
  return w;
}

// A single voxel spreads into the product of the three axes' weights; a constant stays itself;
// a linear ramp along each axis stays itself away from the faces and, at a face, becomes the
// weighted sum of its values with the edge repeated.
TEST(GaussianSmoothing, ImpulseConstantAndRampsGiveTheirDefiningSums) {
  const float sigma = 0.85f;
  const std::vector<double> w = weights(sigma);
  const int r = int(w.size() / 2);
  for (Precision p : {Precision::FP32, Precision::FP16}) {
    const glm::ivec3 n(19, 15, 13);
    const Field3D impulse =
        fieldOf(n, p, [](int i, int j, int k) { return i == 9 && j == 7 && k == 6 ? 1.f : 0.f; });
    const Field3D s = gaussianSmoothed(impulse, sigma, nullptr);
    EXPECT_EQ(s.precision(), Precision::FP32);
    double worst = 0.0, total = 0.0;
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          const int di = i - 9, dj = j - 7, dk = k - 6;
          const bool inside = std::abs(di) <= r && std::abs(dj) <= r && std::abs(dk) <= r;
          const double expect =
              inside ? w[size_t(di + r)] * w[size_t(dj + r)] * w[size_t(dk + r)] : 0.0;
          const double got = s.get(size_t(i + n.x * (j + n.y * k)));
          worst = std::max(worst, std::fabs(got - expect));
          total += got;
        }
    EXPECT_LT(worst, 1e-6);
    EXPECT_NEAR(total, 1.0, 1e-5);

    const Field3D constant =
        gaussianSmoothed(fieldOf(n, p, [](int, int, int) { return 0.75f; }), sigma, nullptr);
    for (size_t v = 0; v < constant.size(); ++v) ASSERT_NEAR(constant.get(v), 0.75f, 1e-6f);
  }
  // Ramps: x, y and z in turn, on a grid long enough for an interior.
  const glm::ivec3 n(12, 11, 10);
  float (*ramps[3])(int, int, int) = {[](int i, int, int) { return 0.5f * float(i); },
                                      [](int, int j, int) { return 0.5f * float(j); },
                                      [](int, int, int k) { return 0.5f * float(k); }};
  for (int axis = 0; axis < 3; ++axis) {
    const Field3D s = gaussianSmoothed(fieldOf(n, Precision::FP32, ramps[axis]), sigma, nullptr);
    const int len = n[axis];
    for (int q = 0; q < len; ++q) {
      double expect = 0.0;
      for (int o = -r; o <= r; ++o)
        expect += w[size_t(o + r)] * 0.5 * std::clamp(q + o, 0, len - 1);
      glm::ivec3 at(3, 4, 5);
      at[axis] = q;
      EXPECT_NEAR(s.get(size_t(at.x + n.x * (at.y + n.y * at.z))), expect, 2e-6)
          << "axis " << axis << " voxel " << q;
    }
  }
  // An axis of one voxel is left alone.
  const Field3D flat = gaussianSmoothed(
      fieldOf({9, 1, 7}, Precision::FP32, [](int i, int, int k) { return float(i + 10 * k); }),
      sigma, nullptr);
  EXPECT_NEAR(flat.get(size_t(4 + 9 * 3)), 34.f, 1e-4f);
}

}  // namespace
}  // namespace visopt
