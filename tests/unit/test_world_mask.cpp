// The world mask held as bits (one per voxel): the engine's ledger entry is ceil(voxels / 8)
// bytes and absent when there is no mask; wrong dims are Usage errors; a field, a bit mask and a
// mask file give the same bits; the kernels' trilinear view of the bits matches sampling the
// same 0/1 values as a field.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/bit_mask_view.h"
#include "core/device_bit_mask.h"
#include "core/field_view.h"
#include "render_fixtures.h"
#include "visopt/bit_mask.h"
#include "visopt/engine.h"
#include "visopt/error.h"
#include "visopt/volume_io.h"

using namespace visopt;

namespace {

// An n-voxel volume on an anisotropic grid, so a transposed index would show.
Volume boxVolume(glm::ivec3 dims) {
  GridSpec g;
  g.dims = dims;
  Volume v;
  v.name = "box";
  v.sourcePath = "test:box";
  v.scalarType = "float32";
  v.valueMin = 0.0;
  v.valueMax = 1.0;
  v.normalized = Field3D("volume", g, Precision::FP32);
  v.normalized.fill(0.5f);
  return v;
}

const LedgerEntry* entryNamed(const MemoryLedger& ledger, const std::string& name,
                              std::vector<LedgerEntry>& storage) {
  storage = ledger.entries();
  for (const LedgerEntry& e : storage)
    if (e.name == name) return &e;
  return nullptr;
}

BitMask randomMask(glm::ivec3 dims, unsigned seed) {
  BitMask m = BitMask::cleared(dims);
  std::mt19937 rng(seed);
  for (size_t i = 0; i < m.voxelCount(); ++i) m.set(i, rng() % 3 == 0);
  return m;
}

}  // namespace

TEST(WorldMask, LedgerHoldsOneBitPerVoxelAndNothingWhenUnused) {
  // 13 x 7 x 5 = 455 voxels: 57 bytes (455 / 8 = 56.875, rounded up).
  const glm::ivec3 dims(13, 7, 5);
  Engine e;
  e.setVolume(boxVolume(dims));
  std::vector<LedgerEntry> storage;
  EXPECT_EQ(entryNamed(e.ledger(), "world-mask", storage), nullptr) << "no mask, no entry";
  EXPECT_EQ(e.worldMask(), nullptr);
  const size_t before = e.ledger().totalBytes();

  e.setWorldMask(randomMask(dims, 3));
  const LedgerEntry* entry = entryNamed(e.ledger(), "world-mask", storage);
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(entry->bytes, 57u);
  EXPECT_EQ(entry->precision, "bit");
  EXPECT_EQ(e.ledger().totalBytes(), before + 57u);

  // Replacing the mask keeps one entry.
  e.setWorldMask(randomMask(dims, 4));
  storage = e.ledger().entries();
  EXPECT_EQ(std::count_if(storage.begin(), storage.end(),
                          [](const LedgerEntry& l) { return l.name == "world-mask"; }),
            1);

  e.clearWorldMask();
  EXPECT_EQ(entryNamed(e.ledger(), "world-mask", storage), nullptr);
  EXPECT_EQ(e.worldMask(), nullptr);
  EXPECT_EQ(e.ledger().totalBytes(), before);
}

TEST(WorldMask, ExactMultipleOfEightHasNoSpareByte) {
  Engine e;
  e.setVolume(boxVolume({8, 4, 2}));  // 64 voxels: 8 bytes
  e.setWorldMask(BitMask::cleared({8, 4, 2}));
  std::vector<LedgerEntry> storage;
  const LedgerEntry* entry = entryNamed(e.ledger(), "world-mask", storage);
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(entry->bytes, 8u);
}

TEST(WorldMask, DimsMustMatchTheVolume) {
  Engine e;
  EXPECT_THROW(e.setWorldMask(BitMask::cleared({4, 4, 4})), Error) << "no volume yet";
  e.setVolume(boxVolume({13, 7, 5}));
  for (glm::ivec3 bad : {glm::ivec3(7, 13, 5), glm::ivec3(13, 7, 4), glm::ivec3(0)}) {
    try {
      e.setWorldMask(BitMask::cleared(bad));
      ADD_FAILURE() << "accepted dims " << bad.x << "x" << bad.y << "x" << bad.z;
    } catch (const Error& err) {
      EXPECT_EQ(err.kind(), ErrorKind::Usage);
      EXPECT_NE(std::string(err.what()).find("13x7x5"), std::string::npos) << err.what();
    }
  }
  BitMask shortBits = BitMask::cleared({13, 7, 5});
  shortBits.bits.pop_back();
  EXPECT_THROW(e.setWorldMask(shortBits), Error);
  EXPECT_EQ(e.worldMask(), nullptr) << "a rejected mask must not be kept";
  Field3D wrong("mask", GridSpec{}, Precision::FP32);
  EXPECT_THROW(e.setWorldMask(wrong), Error);
}

TEST(WorldMask, FieldBitsAndFileAgree) {
  const glm::ivec3 dims(13, 7, 5);
  Engine e;
  e.setVolume(boxVolume(dims));
  const BitMask bits = randomMask(dims, 7);
  e.setWorldMask(bits);
  ASSERT_NE(e.worldMask(), nullptr);
  EXPECT_EQ(*e.worldMask(), bits);

  // The same mask as a field of 0 / 1 (> 0.5 = masked; 0.5 itself is not).
  Volume box = boxVolume(dims);
  Field3D field("mask", box.grid(), Precision::FP32);
  for (size_t i = 0; i < field.size(); ++i) field.set(i, bits.get(i) ? 0.75f : 0.5f);
  e.clearWorldMask();
  e.setWorldMask(field);
  EXPECT_EQ(*e.worldMask(), bits);

  // And as a volume file (non-zero = masked), read through loadWorldMask.
  Volume file = boxVolume(dims);
  for (size_t i = 0; i < file.normalized.size(); ++i)
    file.normalized.set(i, bits.get(i) ? 1.f : 0.f);
  const std::string path = std::string(VISOPT_TEST_TMP) + "/world_mask_bits.mha";
  writeVolume(file, path);
  e.clearWorldMask();
  e.loadWorldMask(path);
  ASSERT_NE(e.worldMask(), nullptr);
  EXPECT_EQ(*e.worldMask(), bits);
  EXPECT_EQ(e.worldMask()->count(), [&] {
    size_t n = 0;
    for (size_t i = 0; i < bits.voxelCount(); ++i) n += bits.get(i) ? 1u : 0u;
    return n;
  }());
}

// The kernels read the bits through BitMaskView; its trilinear sample (used to carry the mask
// to coarser multigrid levels) equals FieldView's sample of the same 0/1 values.
TEST(WorldMask, BitViewSamplesLikeTheField) {
  const glm::ivec3 dims(9, 6, 5);
  const BitMask bits = randomMask(dims, 21);
  const DeviceBitMask device(bits, "mask", nullptr);
  EXPECT_EQ(device.bytes(), (270u + 7u) / 8u);
  EXPECT_EQ(device.toHost(), bits);
  GridSpec g;
  g.dims = dims;
  Field3D field("mask", g, Precision::FP32);
  for (size_t i = 0; i < field.size(); ++i) field.set(i, bits.get(i) ? 1.f : 0.f);
  const FieldView fv(field);
  const BitMaskView bv = device.view();
  for (size_t i = 0; i < bits.voxelCount(); ++i) ASSERT_EQ(bv.get(i), bits.get(i)) << i;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.f, 10.f);
  for (int n = 0; n < 2000; ++n) {
    const glm::vec3 p(u(rng), u(rng), u(rng));
    ASSERT_NEAR(bv.sample(p), fv.sample(p), 1e-6f) << p.x << "," << p.y << "," << p.z;
  }
}
