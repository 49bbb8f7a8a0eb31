// Distributed moment generation (visopt/moment_image.h, MomentPartials): the volume cut into z
// slabs, each slab's partial moments added in any order, equals generateMomentImage's image of
// the whole volume; what a slab must hold and what cannot be split is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "moment_image_checks.h"
#include "visopt/error.h"
#include "visopt/moment_image.h"
#include "visopt/scenes.h"

namespace visopt {
namespace {

// Slices [z0, z1) of a field, as a rank holding only those would have them.
Field3D slices(const Field3D& whole, int z0, int z1) {
  GridSpec g = whole.grid();
  g.dims.z = z1 - z0;
  Field3D out("slab", g, Precision::FP32);
  const size_t plane = size_t(g.dims.x) * size_t(g.dims.y);
  for (size_t i = 0; i < plane * size_t(z1 - z0); ++i)
    out.set(i, whole.get(size_t(z0) * plane + i));
  return out;
}

// The image from slabs cut at `cuts` (0 < cuts < dims.z, ascending), each holding just the
// slices it needs, added in the order `order` into separate partials that are then merged.
MomentImage fromSlabs(const Volume& v, const Camera& cam, const MomentImageSettings& s,
                      const std::vector<int>& cuts, bool reversed) {
  const int nz = v.grid().dims.z, halo = momentSlabHalo(s);
  std::vector<int> bounds = {0};
  bounds.insert(bounds.end(), cuts.begin(), cuts.end());
  bounds.push_back(nz);
  std::vector<size_t> order(bounds.size() - 1);
  std::iota(order.begin(), order.end(), size_t(0));
  if (reversed) std::reverse(order.begin(), order.end());
  MomentPartials total = emptyMomentPartials(s);
  for (size_t b : order) {
    const int own0 = bounds[b], own1 = bounds[b + 1];
    const int z0 = std::max(0, own0 - halo), z1 = std::min(nz, own1 + halo);
    MomentPartials part = emptyMomentPartials(s);
    addMomentSlab(part, slices(v.normalized, z0, z1), z0, own0, own1, v.grid(), cam, s);
    mergeMomentPartials(total, part);
  }
  return finishMomentImage(total, v.grid(), cam, s, v.valueMin, v.valueMax);
}

TEST(MomentSlabs, SlabsInAnyOrderGiveTheWholeVolumesImage) {
  for (const char* name : {"marschner-lobb", "shepp-logan"}) {
    const BuiltinScene sc = makeBuiltinScene(name, 40, Precision::FP32);
    const Volume& v = sc.volume;
    MomentImageSettings s;
    s.width = 40;
    s.height = 32;
    // Views from above, the side and below: rays cross the slabs up, across and down.
    for (float el : {60.f, 0.f, -45.f}) {
      const Camera cam = Camera::orbitBounds(v.grid().worldBounds(), 30.f, el, 2.5f);
      const MomentImage whole = generateMomentImage(v, cam, s);
      int hit = 0;
      for (uint8_t c : whole.counts) hit += c > 0;
      ASSERT_GT(hit, 200) << name << ": the view must see the volume";
      const int nz = v.grid().dims.z;
      for (const auto& cuts :
           {std::vector<int>{nz / 2}, std::vector<int>{7, 19, 20, 33}, std::vector<int>{1}}) {
        for (bool reversed : {false, true}) {
          const std::string what = std::string(name) + " el " + std::to_string(int(el)) +
                                   " slabs " + std::to_string(cuts.size() + 1) +
                                   (reversed ? " reversed" : "");
          testing::expectSameMomentImage(fromSlabs(v, cam, s, cuts, reversed), whole, what);
        }
      }
    }
  }
}

TEST(MomentSlabs, OneSlabPerSliceAndACoarseStepStillAddUp) {
  const BuiltinScene sc = makeBuiltinScene("marschner-lobb", 24, Precision::FP32);
  const Volume& v = sc.volume;
  MomentImageSettings s;
  s.width = 24;
  s.height = 24;
  s.stepVoxels = 2.5f;  // pieces reach further: a wider halo
  s.errorThreshold = 0.f;
  const Camera cam = Camera::orbitBounds(v.grid().worldBounds(), 10.f, 35.f, 2.5f);
  std::vector<int> cuts;
  for (int z = 1; z < v.grid().dims.z; ++z) cuts.push_back(z);
  testing::expectSameMomentImage(fromSlabs(v, cam, s, cuts, false), generateMomentImage(v, cam, s),
                                 "a slab per slice");
}

TEST(MomentSlabs, ASlabMissingItsHaloOrAnUncertaintyIsRefused) {
  const BuiltinScene sc = makeBuiltinScene("marschner-lobb", 24, Precision::FP32);
  const Volume& v = sc.volume;
  MomentImageSettings s;
  s.width = 8;
  s.height = 8;
  const Camera cam = Camera::orbitBounds(v.grid().worldBounds(), 10.f, 35.f, 2.5f);
  MomentPartials p = emptyMomentPartials(s);
  // Owns 8..16 but holds only those slices: the pieces' last samples and stencils lie beyond.
  EXPECT_THROW(addMomentSlab(p, slices(v.normalized, 8, 16), 8, 8, 16, v.grid(), cam, s), Error);
  EXPECT_THROW(addMomentSlab(p, slices(v.normalized, 0, 24), 0, 16, 30, v.grid(), cam, s), Error);
  MomentImageSettings other = s;
  other.moments = 20;
  EXPECT_THROW(addMomentSlab(p, v.normalized, 0, 0, 24, v.grid(), cam, other), Error);
  MomentImageSettings withUncertainty = s;
  withUncertainty.uncertaintyQuantile = 0.9f;
  EXPECT_THROW(finishMomentImage(p, v.grid(), cam, withUncertainty, 0.0, 1.0), Error);
  // A slab owning nothing the view sees adds nothing: the image is the empty one.
  const MomentImage none = finishMomentImage(p, v.grid(), cam, s, 0.0, 1.0);
  for (uint8_t c : none.counts) EXPECT_EQ(c, 0);
}

}  // namespace
}  // namespace visopt
