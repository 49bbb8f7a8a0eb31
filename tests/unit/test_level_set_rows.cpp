// The vectorised CPU row loop (kernels/level_set_step.h, sweepStepRow) of the level-set step and
// of redistancing against the per-voxel path the CUDA backend runs (sweepVoxel), and the integer
// fp16 conversions that row loop uses against the reference conversions of core/half.h.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/device_bit_mask.h"
#include "core/half.h"
#include "kernels/level_set_step.h"
#include "kernels/redistance.h"

using namespace visopt;

namespace {

uint32_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

float floatOf(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

// A test field's storage value (float or Half) from a float, and back.
template <class Store>
Store storeAs(float v) {
  if constexpr (std::is_same_v<Store, Half>)
    return floatToHalf(v);
  else
    return v;
}
float loadAs(float v) {
  return v;
}
float loadAs(Half v) {
  return halfToFloat(v);
}

}  // namespace

TEST(Fp16RowConversions, EveryHalfWidensToTheSameFloat) {
  int nan = 0;
  for (uint32_t b = 0; b < 65536u; ++b) {
    const Half h{uint16_t(b)};
    const float ref = halfToFloat(h), row = halfToFloatRow(h);
    if (std::isnan(ref)) {
      ++nan;
      ASSERT_TRUE(std::isnan(row)) << std::hex << b;
      ASSERT_EQ(std::signbit(ref), std::signbit(row)) << std::hex << b;
    } else {
      ASSERT_EQ(bitsOf(ref), bitsOf(row)) << std::hex << b << " " << ref << " " << row;
    }
  }
  EXPECT_EQ(nan, 2 * 1023);  // the test saw every NaN pattern
}

// Every float of magnitude <= 65504 whose dropped 13 mantissa bits sit at or next to a rounding
// boundary (the ties and their neighbours), every subnormal-half range float with a stride, and
// a strided sweep of the rest.
TEST(Fp16RowConversions, NarrowingRoundsLikeTheReference) {
  const uint32_t top = bitsOf(65504.f);
  size_t checked = 0;
  auto check = [&](uint32_t u) {
    if (u > top) return;
    for (uint32_t sign : {0u, 0x80000000u}) {
      const float v = floatOf(u | sign);
      const Half ref = floatToHalf(v), row = floatToHalfRow(v);
      ASSERT_EQ(ref.bits, row.bits) << std::hex << (u | sign) << " " << v;
      ++checked;
    }
  };
  for (uint32_t hi = 0; hi <= (top >> 13); ++hi)
    for (uint32_t lo : {0x0000u, 0x0001u, 0x0fffu, 0x1000u, 0x1001u, 0x1fffu})
      check((hi << 13) | lo);
  for (uint32_t u = 0; u < bitsOf(0x1p-14f); u += 61) check(u);  // halves' subnormals and below
  for (uint32_t u = 0; u <= top; u += 4099) check(u);
  std::printf("fp16 narrowing: %zu floats checked\n", checked);
  EXPECT_GT(checked, 1000000u);
}

namespace {

struct Case {
  glm::ivec3 dims;
  bool fp16;
  bool withMask;
  int order;
};

template <class A, int Order>
void compareRowsWithVoxels(const Case& c) {
  using Store = std::conditional_t<std::is_same_v<A, Fp16Access>, Half, float>;
  const size_t n = size_t(c.dims.x) * size_t(c.dims.y) * size_t(c.dims.z);
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> noise(-0.3f, 0.3f), unit(0.f, 1.f);
  const auto store = storeAs<Store>;
  std::vector<Store> phi(n), phi0(n), ghat(n), outRows(n), outVoxels(n);
  const glm::vec3 centre = glm::vec3(c.dims) * 0.5f + glm::vec3(0.3f, -0.2f, 0.1f);
  const float radius = 0.3f * float(std::min({c.dims.x, c.dims.y, c.dims.z}));
  for (int k = 0; k < c.dims.z; ++k)
    for (int j = 0; j < c.dims.y; ++j)
      for (int i = 0; i < c.dims.x; ++i) {
        const size_t v = (size_t(k) * size_t(c.dims.y) + size_t(j)) * size_t(c.dims.x) + size_t(i);
        const float d = glm::length(glm::vec3(i, j, k) - centre) - radius;
        phi[v] = store(d + noise(rng));
        phi0[v] = store(d);
        ghat[v] = store(unit(rng));
      }
  DeviceBitMask mask(c.dims, "mask", nullptr);
  if (c.withMask)
    for (size_t w = 0; w < DeviceBitMask::wordCount(c.dims); ++w)
      mask.words()[w] = uint8_t(rng() & 0x91u);  // about a third of the voxels
  LevelSetStepKernel<A, Order> k;
  k.phi = A{phi.data()};
  k.phi0 = A{phi0.data()};
  k.ghat = A{ghat.data()};
  if (c.withMask) k.mask = mask.view();
  k.dims = c.dims;
  k.spacing = glm::vec3(1.f, 1.3f, 0.7f);
  k.dt = 0.05f;
  k.lambda = 0.4f;
  k.kappaMax = 1.f / 0.7f;

  k.out = A{outVoxels.data()};
  ChangeSums voxels;
  for (int64_t v = 0; v < int64_t(n); ++v) voxels = voxels + k.voxel(v);
  k.out = A{outRows.data()};
  ChangeSums rows;
  for (int64_t r = 0; r < int64_t(c.dims.y) * c.dims.z; ++r) rows = rows + k.row(r);

  size_t differ = 0;
  for (size_t v = 0; v < n; ++v) {
    const float a = loadAs(outRows[v]), b = loadAs(outVoxels[v]);
    ASSERT_TRUE(std::isfinite(a)) << v;
    // The vector code may contract a*b+c into an FMA: a few ulps of fp32, never more, which in
    // fp16 storage can at most round to the neighbouring half.
    const float ulps = std::is_same_v<Store, Half> ? 1e-3f : 1e-6f;
    ASSERT_NEAR(a, b, ulps * std::max(1.f, std::fabs(b))) << "voxel " << v;
    differ += a != b;
  }
  std::printf("%dx%dx%d %s order %d%s: %zu of %zu voxels differ in the last bits\n", c.dims.x,
              c.dims.y, c.dims.z, c.fp16 ? "fp16" : "fp32", Order, c.withMask ? " masked" : "",
              differ, n);
  const double rel = std::is_same_v<Store, Half> ? 1e-3 : 1e-5;
  EXPECT_NEAR(rows.maxAbs, voxels.maxAbs, rel * std::max(1.f, voxels.maxAbs));
  EXPECT_NEAR(rows.sumAbs, voxels.sumAbs, rel * std::max(1.0, voxels.sumAbs));
  EXPECT_NEAR(rows.sumSquared, voxels.sumSquared, rel * std::max(1.0, voxels.sumSquared));
  EXPECT_GT(voxels.sumAbs, 0.0) << "the step moved something";
}

void compare(const Case& c) {
  if (c.fp16)
    c.order == 1 ? compareRowsWithVoxels<Fp16Access, 1>(c)
                 : compareRowsWithVoxels<Fp16Access, 2>(c);
  else
    c.order == 1 ? compareRowsWithVoxels<Fp32Access, 1>(c)
                 : compareRowsWithVoxels<Fp32Access, 2>(c);
}

}  // namespace

// Rows of 37 voxels: two 16-voxel chunks whose second overlaps the first (33 interior voxels),
// rows of 20 (exactly one chunk), rows too short for a chunk, and face rows in y and z.
TEST(LevelSetRows, RowLoopMatchesThePerVoxelPath) {
  for (glm::ivec3 dims :
       {glm::ivec3(37, 9, 7), glm::ivec3(20, 6, 5), glm::ivec3(11, 5, 6), glm::ivec3(37, 1, 3)})
    for (bool fp16 : {false, true})
      for (bool withMask : {false, true})
        for (int order : {1, 2}) {
          SCOPED_TRACE(testing::Message()
                       << dims.x << "x" << dims.y << "x" << dims.z << (fp16 ? " fp16" : " fp32")
                       << " order " << order << (withMask ? " masked" : ""));
          compare(Case{dims, fp16, withMask, order});
        }
}

namespace {

// A redistancing kernel on `in` (anisotropic spacing 1 x 1.3 x 0.7, the ENO2 pseudo-time step),
// holding voxels near `base` when one is given, counting the voxels within two of the smallest
// spacing as near the surface.
template <class A, int Order, class Store>
RedistanceKernel<A, Order> redistanceKernelOn(Store* in, Store* base, glm::ivec3 dims,
                                              bool initialise) {
  RedistanceKernel<A, Order> k;
  k.in = A{in};
  k.dims = dims;
  k.spacing = glm::vec3(1.f, 1.3f, 0.7f);
  k.dxMin = 0.7f;
  k.dtau = 0.3f * k.dxMin;
  k.initialise = initialise;
  if (base) {
    k.base = A{base};
    k.keepWithin = 0.05f * k.dxMin;
  } else {
    k.withoutBase();
  }
  k.nearBand = 2.f * k.dxMin;
  return k;
}

// Redistancing (kernels/redistance.h) through sweepStepRow, whole rows and spans of rows (the
// band path), against sweepVoxel: the first pass (subcell initialisation) and a later one, with
// and without a base SDF whose nearby voxels are held.
template <class A, int Order>
void compareRedistanceRowsWithVoxels(glm::ivec3 dims, bool initialise, bool withBase) {
  using Store = std::conditional_t<std::is_same_v<A, Fp16Access>, Half, float>;
  const size_t n = size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> noise(-0.4f, 0.4f);
  const auto store = storeAs<Store>;
  std::vector<Store> in(n), base(n), outRows(n), outVoxels(n), outSpans(n);
  const glm::vec3 centre = glm::vec3(dims) * 0.5f + glm::vec3(0.2f, -0.3f, 0.15f);
  const float radius = 0.3f * float(std::min({dims.x, dims.y, dims.z}));
  for (int k = 0; k < dims.z; ++k)
    for (int j = 0; j < dims.y; ++j)
      for (int i = 0; i < dims.x; ++i) {
        const size_t v = (size_t(k) * size_t(dims.y) + size_t(j)) * size_t(dims.x) + size_t(i);
        const float d = glm::length(glm::vec3(i, j, k) - centre) - radius;
        base[v] = store(d);
        // Half the voxels keep their base value (held when withBase), the rest are distorted.
        in[v] = store((v % 2) ? d : d * (1.3f + noise(rng)));
      }
  RedistanceKernel<A, Order> k =
      redistanceKernelOn<A, Order>(in.data(), withBase ? base.data() : nullptr, dims, initialise);
  k.out = A{outVoxels.data()};
  ChangeSums voxels;
  for (int64_t v = 0; v < int64_t(n); ++v) voxels = voxels + k.voxel(v);
  k.out = A{outRows.data()};
  ChangeSums rows;
  for (int64_t r = 0; r < int64_t(dims.y) * dims.z; ++r) rows = rows + k.row(r);
  // Spans [3, nx - 5) and the rest of each row, as the band path splits rows.
  k.out = A{outSpans.data()};
  ChangeSums spans;
  const int cut0 = std::min(3, dims.x), cut1 = std::max(cut0, dims.x - 5);
  for (int64_t r = 0; r < int64_t(dims.y) * dims.z; ++r)
    spans = spans + k.span(r, 0, cut0) + k.span(r, cut0, cut1) + k.span(r, cut1, dims.x);
  size_t differ = 0;
  const float ulps = std::is_same_v<Store, Half> ? 1e-3f : 1e-6f;
  for (size_t v = 0; v < n; ++v) {
    const float a = loadAs(outRows[v]), b = loadAs(outVoxels[v]), c = loadAs(outSpans[v]);
    ASSERT_TRUE(std::isfinite(a)) << v;
    ASSERT_NEAR(a, b, ulps * std::max(1.f, std::fabs(b))) << "voxel " << v;
    ASSERT_NEAR(c, b, ulps * std::max(1.f, std::fabs(b))) << "voxel " << v;
    differ += a != b;
  }
  std::printf("redistance %dx%dx%d %s order %d%s%s: %zu of %zu voxels differ in the last bits\n",
              dims.x, dims.y, dims.z, std::is_same_v<Store, Half> ? "fp16" : "fp32", Order,
              initialise ? " first pass" : "", withBase ? " with base" : "", differ, n);
  const double rel = std::is_same_v<Store, Half> ? 1e-3 : 1e-5;
  for (const ChangeSums* s : {&rows, &spans}) {
    EXPECT_NEAR(s->maxAbs, voxels.maxAbs, rel * std::max(1.f, voxels.maxAbs));
    EXPECT_NEAR(s->sumSquared, voxels.sumSquared, rel * std::max(1.0, voxels.sumSquared));
    EXPECT_NEAR(s->nearSumSquared, voxels.nearSumSquared,
                rel * std::max(1.0, voxels.nearSumSquared));
    EXPECT_EQ(s->nearCount, voxels.nearCount);
  }
  EXPECT_GT(voxels.sumAbs, 0.0) << "the pass moved something";
}

}  // namespace

TEST(RedistanceRows, RowLoopMatchesThePerVoxelPath) {
  for (glm::ivec3 dims :
       {glm::ivec3(37, 9, 7), glm::ivec3(20, 6, 5), glm::ivec3(11, 5, 6), glm::ivec3(37, 1, 3)})
    for (bool initialise : {true, false})
      for (bool withBase : {false, true}) {
        SCOPED_TRACE(testing::Message()
                     << dims.x << "x" << dims.y << "x" << dims.z << (initialise ? " first" : "")
                     << (withBase ? " base" : ""));
        compareRedistanceRowsWithVoxels<Fp32Access, 2>(dims, initialise, withBase);
        compareRedistanceRowsWithVoxels<Fp32Access, 1>(dims, initialise, withBase);
        compareRedistanceRowsWithVoxels<Fp16Access, 2>(dims, initialise, withBase);
      }
}

namespace {

// Spans of every length from 1 to 20 voxels at positions along a 40-voxel row, from the row's
// first voxel to its last (the band path's runs of bricks, some shorter than a 16-lane chunk):
// each voxel of a span gets the per-voxel path's value, nothing outside the span is written (a
// chunk reaching past a short span must leave the band's halo alone), and the span's sums are
// the per-voxel sums over its voxels.
template <class A, class K>
void compareShortSpansWithVoxels(
    K k, glm::ivec3 dims,
    std::vector<std::conditional_t<std::is_same_v<A, Fp16Access>, Half, float>>& scratch) {
  using Store = std::conditional_t<std::is_same_v<A, Fp16Access>, Half, float>;
  const size_t n = size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
  std::vector<Store> reference(n);
  k.out = A{reference.data()};
  std::vector<ChangeSums> perVoxel(n);
  for (int64_t v = 0; v < int64_t(n); ++v) perVoxel[size_t(v)] = k.voxel(v);
  const float ulps = std::is_same_v<Store, Half> ? 1e-3f : 1e-6f;
  const float sentinel = 2048.f;  // exact in fp16, far from any value the kernels write
  int spans = 0;
  for (int64_t r = 0; r < int64_t(dims.y) * dims.z; r += 3)
    for (int x0 : {0, 1, 2, 3, 5, 9, 16, 21, 24, 30, 37, 39})
      for (int len = 1; len <= 20 && x0 + len <= dims.x; ++len) {
        const int x1 = x0 + len;
        const size_t first = size_t(r) * size_t(dims.x);
        for (int x = 0; x < dims.x; ++x) scratch[first + size_t(x)] = storeAs<Store>(sentinel);
        k.out = A{scratch.data()};
        const ChangeSums got = k.span(r, x0, x1);
        ChangeSums want;
        for (int x = x0; x < x1; ++x) want = want + perVoxel[first + size_t(x)];
        for (int x = 0; x < dims.x; ++x) {
          const float a = loadAs(scratch[first + size_t(x)]);
          if (x < x0 || x >= x1) {
            ASSERT_EQ(a, sentinel)
                << "row " << r << " span [" << x0 << ", " << x1 << ") wrote voxel " << x;
          } else {
            const float b = loadAs(reference[first + size_t(x)]);
            ASSERT_NEAR(a, b, ulps * std::max(1.f, std::fabs(b)))
                << "row " << r << " span [" << x0 << ", " << x1 << ") voxel " << x;
          }
        }
        const double rel = std::is_same_v<Store, Half> ? 1e-3 : 1e-5;
        ASSERT_NEAR(got.maxAbs, want.maxAbs, rel * std::max(1.f, want.maxAbs));
        ASSERT_NEAR(got.sumSquared, want.sumSquared, rel * std::max(1.0, want.sumSquared));
        ASSERT_NEAR(got.nearSumSquared, want.nearSumSquared,
                    rel * std::max(1.0, want.nearSumSquared));
        ASSERT_EQ(got.nearCount, want.nearCount);
        ASSERT_NEAR(got.insideRiseMax, want.insideRiseMax, rel * std::max(1.f, want.insideRiseMax));
        ++spans;
      }
  EXPECT_GT(spans, 500);
}

template <class A>
void shortSpans() {
  using Store = std::conditional_t<std::is_same_v<A, Fp16Access>, Half, float>;
  const glm::ivec3 dims(40, 7, 6);
  const size_t n = size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(-0.4f, 0.4f), unit(0.f, 1.f);
  std::vector<Store> phi(n), phi0(n), ghat(n), scratch(n);
  const glm::vec3 centre(19.6f, 3.2f, 2.9f);
  for (size_t v = 0; v < n; ++v) {
    const glm::vec3 x(float(v % 40), float((v / 40) % 7), float(v / 280));
    const float d = glm::length(x - centre) - 2.6f;
    phi0[v] = storeAs<Store>(d);
    phi[v] = storeAs<Store>((v % 2) ? d : d * (1.3f + noise(rng)));
    ghat[v] = storeAs<Store>(unit(rng));
  }
  compareShortSpansWithVoxels<A>(redistanceKernelOn<A, 2>(phi.data(), phi0.data(), dims, true),
                                 dims, scratch);

  LevelSetStepKernel<A, 2> step;
  step.phi = A{phi.data()};
  step.phi0 = A{phi0.data()};
  step.ghat = A{ghat.data()};
  step.dims = dims;
  step.spacing = glm::vec3(1.f, 1.3f, 0.7f);
  step.dt = 0.05f;
  step.lambda = 0.4f;
  step.kappaMax = 1.f / 0.7f;
  compareShortSpansWithVoxels<A>(step, dims, scratch);
}

}  // namespace

TEST(RedistanceRows, ShortSpansMatchThePerVoxelPathAndWriteNothingOutside) {
  shortSpans<Fp32Access>();
  shortSpans<Fp16Access>();
}
