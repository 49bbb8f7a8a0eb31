// The CPU backend's lane gathers (host/simd_gather.h) against plain loads: fp32 and fp16 fields
// of odd and even sizes allocated as fields are (exec::allocate), indices at even and odd
// positions, repeated, and at the first and last value (the fp16 gather reads the aligned 32-bit
// word holding each value; the last value of an odd-sized field is the low half of a word whose
// high half lies past the field's end, inside its allocation). The portable form, which a CPU
// without AVX-512 runs, is held to the same loads.
#include <algorithm>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "core/half.h"
#include "exec/parallel.h"
#include "host/simd_gather.h"

using namespace visopt;

namespace {

template <class Storage>
void expectGathersLoad(int size) {
  SCOPED_TRACE(std::string(std::is_same_v<Storage, Half> ? "fp16" : "fp32") + ", " +
               std::to_string(size) + " values");
  Storage* data = static_cast<Storage*>(exec::allocate(sizeof(Storage) * size_t(size)));
  std::vector<float> expected(static_cast<size_t>(size), 0.f);
  std::mt19937 rng(size);
  std::uniform_real_distribution<float> u(-100.f, 100.f);
  for (int i = 0; i < size; ++i) {
    const float v = u(rng);
    if constexpr (std::is_same_v<Storage, Half>) {
      data[i] = floatToHalf(v);
      expected[size_t(i)] = halfToFloat(data[i]);
    } else {
      data[i] = v;
      expected[size_t(i)] = v;
    }
  }
  std::uniform_int_distribution<int> pick(0, size - 1);
  for (int round = 0; round < 200; ++round) {
    alignas(64) int index[kGatherLanes];
    alignas(64) float simd[kGatherLanes], portable[kGatherLanes];
    for (int l = 0; l < kGatherLanes; ++l) index[l] = pick(rng);
    if (round == 0)
      for (int l = 0; l < kGatherLanes; ++l) index[l] = l % 2 == 0 ? size - 1 : 0;
    if (round == 1)
      for (int l = 0; l < kGatherLanes; ++l) index[l] = std::max(0, size - 1 - l % 3);
    gatherLanes<Storage>(data, index, simd);
    gatherLanesPortable<Storage>(data, index, portable);
    for (int l = 0; l < kGatherLanes; ++l) {
      ASSERT_EQ(simd[l], expected[size_t(index[l])]) << "lane " << l << ", index " << index[l];
      ASSERT_EQ(portable[l], expected[size_t(index[l])]) << "lane " << l;
    }
  }
  exec::deallocate(data);
}

}  // namespace

TEST(SimdGather, LanesLoadWhatPlainLoadsLoad) {
  for (int size : {1, 2, 17, 32, 33, 4097}) {
    expectGathersLoad<float>(size);
    expectGathersLoad<Half>(size);
  }
}
