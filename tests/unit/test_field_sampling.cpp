// Dense fields in fp32 / fp16, trilinear sampling against hand-computed values, the memory
// ledger, and the exec layer's parallelFor / reduce and timings.
#include <cmath>

#include <gtest/gtest.h>

#include "core/field_view.h"
#include "core/half.h"
#include "exec/parallel.h"
#include "visopt/field.h"
#include "visopt/memory_ledger.h"

using namespace visopt;

TEST(Half, RoundTripAndRounding) {
  for (float v : {0.f, 1.f, -2.5f, 0.1f, 1000.f, 65504.f, 6.1e-5f}) {
    float r = halfToFloat(floatToHalf(v));
    EXPECT_NEAR(r, v, std::abs(v) * 1e-3f + 1e-7f) << v;
  }
  EXPECT_EQ(floatToHalf(1.f).bits, 0x3c00);
  EXPECT_EQ(floatToHalf(-2.f).bits, 0xc000);
  EXPECT_TRUE(std::isinf(halfToFloat(floatToHalf(1e6f))));
  EXPECT_EQ(halfToFloat(floatToHalf(1e-9f)), 0.f);  // below the smallest subnormal
}

class FieldPrecision : public ::testing::TestWithParam<Precision> {};

TEST_P(FieldPrecision, TrilinearMatchesHandComputedValues) {
  GridSpec g;
  g.dims = {3, 2, 2};
  Field3D f("test", g, GetParam());
  // f(i,j,k) = i + 2j + 4k is linear, so trilinear interpolation is exact.
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) f.set(g.linearIndex(i, j, k), float(i + 2 * j + 4 * k));
  FieldView v(f);
  EXPECT_FLOAT_EQ(v.sample({0.5f, 0.5f, 0.5f}), 0.5f + 1.f + 2.f);
  EXPECT_FLOAT_EQ(v.sample({1.25f, 0.f, 1.f}), 1.25f + 4.f);
  EXPECT_FLOAT_EQ(v.sample({2.f, 1.f, 1.f}), 8.f);
  // Clamped outside.
  EXPECT_FLOAT_EQ(v.sample({-3.f, 0.f, 0.f}), 0.f);
  EXPECT_FLOAT_EQ(v.sample({9.f, 9.f, 9.f}), 8.f);
  // Non-linear corner mix: only one corner set.
  f.fill(0.f);
  f.set(g.linearIndex(1, 1, 1), 1.f);
  EXPECT_NEAR(v.sample({0.5f, 0.5f, 0.5f}), 0.125f, 1e-6f);
  EXPECT_NEAR(v.sample({0.75f, 0.5f, 1.f}), 0.75f * 0.5f, 1e-6f);
}

TEST_P(FieldPrecision, LedgerReportsBytesAndForgetsFreedFields) {
  MemoryLedger ledger;
  GridSpec g;
  g.dims = {8, 4, 2};
  {
    Field3D a("alpha", g, GetParam(), &ledger);
    Field3D b("beta", g, Precision::FP32, &ledger);
    auto e = ledger.entries();
    ASSERT_EQ(e.size(), 2u);
    EXPECT_EQ(e[0].name, "alpha");
    EXPECT_EQ(e[0].bytes, 64u * bytesPerValue(GetParam()));
    EXPECT_EQ(e[1].bytes, 256u);
    EXPECT_EQ(ledger.totalBytes(), 64u * bytesPerValue(GetParam()) + 256u);
    Field3D moved = std::move(a);
    EXPECT_EQ(ledger.entries().size(), 2u);
  }
  EXPECT_EQ(ledger.totalBytes(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Precisions, FieldPrecision,
                         ::testing::Values(Precision::FP32, Precision::FP16));

TEST(Exec, ParallelForReduceAndNamedTimings) {
  resetStageTimings();
  std::vector<int> hits(10000, 0);
  int* p = hits.data();
  exec::parallelFor("test-fill", 10000, [=](int64_t i) { p[i] += int(i % 7); });
  long long sum = exec::reduce(
      "test-sum", 10000, 0LL, [=](int64_t i) { return (long long)p[i]; },
      [](long long a, long long b) { return a + b; });
  long long expected = 0;
  for (int i = 0; i < 10000; ++i) expected += i % 7;
  EXPECT_EQ(sum, expected);
  auto t = stageTimings();
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].name, "test-fill");
  EXPECT_EQ(t[0].calls, 1);
  EXPECT_EQ(t[0].items, 10000.0);
  EXPECT_EQ(t[1].name, "test-sum");
}

TEST(Field, RenameMovesTheLedgerEntry) {
  MemoryLedger a, b;
  GridSpec g;
  g.dims = {4, 4, 4};
  Field3D f("old", g, Precision::FP16, &a);
  f.rename("new", &b);
  EXPECT_EQ(a.totalBytes(), 0u);
  ASSERT_EQ(b.entries().size(), 1u);
  EXPECT_EQ(b.entries()[0].name, "new");
  EXPECT_EQ(b.entries()[0].bytes, 128u);
  EXPECT_EQ(f.name(), "new");
}
