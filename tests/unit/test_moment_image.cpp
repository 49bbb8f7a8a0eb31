// Moment images end to end (Rapp et al. 2022; visopt/moment_image.h): the moments of a pixel's
// ray are those of its density samples, half-pixel centres, the moment count, rendering a
// moment image against rendering the volume with the same transfer function, pre-integration
// of a thin feature, and the .vmi file with what a broken one must not do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <zlib.h>

#include "core/frustum_map.h"
#include "kernels/moment_image.h"
#include "kernels/p_square.h"
#include "visopt/error.h"
#include "visopt/frustum.h"
#include "visopt/moment_image.h"
#include "visopt/scenes.h"

namespace visopt {
namespace {

constexpr double kPi = 3.14159265358979323846;

BuiltinScene scene(const char* name = "marschner-lobb", int resolution = 40) {
  return makeBuiltinScene(name, resolution, Precision::FP32);
}

Camera viewOf(const BuiltinScene& s) {
  return Camera::orbitBounds(s.volume.grid().worldBounds(), s.azimuthDeg, s.elevationDeg,
                             s.distanceInRadii);
}

// A smooth density on a 40^3 grid (wavelengths of 20-40 voxels), framed like a scene.
Volume smoothVolume() {
  Volume v;
  v.name = "smooth";
  GridSpec g;
  g.dims = glm::ivec3(40);
  v.normalized = Field3D("smooth", g, Precision::FP32);
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i)
        v.normalized.set(g.linearIndex(i, j, k),
                         float(0.5 + 0.3 * std::sin(i / 6.0) * std::cos(j / 5.0) +
                               0.15 * std::sin(k / 4.0 + 1.0)));
  return v;
}

Camera smoothView(const Volume& v) {
  return Camera::orbitBounds(v.grid().worldBounds(), 30.f, 20.f, 2.5f);
}

MomentImageSettings small(int moments = 60, float error = 0.f) {
  MomentImageSettings m;
  m.width = 40;
  m.height = 32;
  m.moments = moments;
  m.errorThreshold = error;
  return m;
}

TEST(MomentImage, AHitPixelsMomentsAreThoseOfItsDensitySamples) {
  const Volume volume = smoothVolume();
  const MomentImageSettings settings = small(30);
  const MomentImage image = generateMomentImage(volume, smoothView(volume), settings);
  const std::vector<uint64_t> offsets = image.offsets();
  int checked = 0;
  for (int y = 4; y < image.height; y += 9)
    for (int x = 5; x < image.width; x += 11) {
      const int64_t p = int64_t(y) * image.width + x;
      if (image.counts[p] == 0) continue;
      ASSERT_EQ(image.counts[p], 31);  // threshold 0 keeps all
      // The same ray sampled densely: its moments by the trapezoid rule on cos(j phi) s(phi).
      const int n = 4001;
      const std::vector<float> v = sampleRay(volume, image, x, y, n);
      const double lo = image.lower[p], hi = image.upper[p];
      for (int j = 0; j <= 30; j += 5) {
        double c = 0.0;
        for (int k = 0; k < n; ++k) {
          const double phi = -kPi + kPi * k / (n - 1);
          const double w = (k == 0 || k == n - 1) ? 0.5 : 1.0;
          c += w * v[k] * std::cos(j * phi) * (kPi / (n - 1)) / kPi;
        }
        const double rescaled = j == 0 ? (c - lo) / (hi - lo) : c / (hi - lo);
        // Sampled at 0.5 voxel in generation against 4001 samples here, of a smooth density.
        EXPECT_NEAR(image.moments[offsets[p] + j], rescaled, 2e-3) << x << "," << y << " j=" << j;
      }
      // The bounds of Eq. 5 enclose the samples by the margin.
      float vmin = 1.f, vmax = 0.f;
      for (float f : v) {
        vmin = std::min(vmin, f);
        vmax = std::max(vmax, f);
      }
      EXPECT_NEAR(lo, vmin - settings.boundsMargin, 0.02);
      EXPECT_NEAR(hi, vmax + settings.boundsMargin, 0.02);
      ++checked;
    }
  EXPECT_GE(checked, 4);
}

TEST(MomentImage, PixelRaysGoThroughPixelCentres) {
  // An odd-sized image: the middle pixel's ray is the view axis (half-pixel centres; the
  // reference code's rays sit half a pixel off).
  const BuiltinScene s = scene();
  const Camera cam = viewOf(s);
  const FrustumMap f(FrustumGrid::forCamera(cam, 41, 31, s.volume.grid().worldBounds(), 1, 1.f));
  const glm::vec3 d = f.rayDirection(20.f, 15.f);
  EXPECT_LT(glm::length(d - glm::normalize(cam.target - cam.eye)), 1e-6f);
}

TEST(MomentImage, TheCountKeepsTheFewestMomentsWithinTheErrorAndMissesStoreNone) {
  // Marschner-Lobb at 40^3 is all high frequencies: 0.01 keeps 63 % of 61 moments; a smooth
  // density 40 % (both measured).
  const Volume smooth = smoothVolume();
  const MomentImage smoothAll = generateMomentImage(smooth, smoothView(smooth), small(60, 0.f));
  const MomentImage smoothFew = generateMomentImage(smooth, smoothView(smooth), small(60, 0.01f));
  EXPECT_LT(smoothFew.moments.size(), smoothAll.moments.size() / 2);
  const BuiltinScene s = scene();
  const MomentImage all = generateMomentImage(s.volume, viewOf(s), small(60, 0.f));
  const MomentImage few = generateMomentImage(s.volume, viewOf(s), small(60, 0.01f));
  EXPECT_LT(few.moments.size(), all.moments.size());
  const std::vector<uint64_t> offsets = all.offsets();
  int missed = 0;
  for (size_t p = 0; p < all.pixelCount(); ++p) {
    EXPECT_EQ(all.counts[p] == 0, few.counts[p] == 0);
    missed += all.counts[p] == 0;
    if (few.counts[p] == 0 || few.counts[p] == 61) continue;
    std::vector<double> c(61);
    for (int j = 0; j <= 60; ++j) c[j] = all.moments[offsets[p] + j];
    EXPECT_LE(truncationError(c.data(), few.counts[p] - 1, 60), 0.01) << "pixel " << p;
  }
  EXPECT_GT(missed, 0);  // the corners of the view miss the volume
}

TEST(MomentImage, TheReconstructedRayFollowsTheDensity) {
  const BuiltinScene s = scene();
  const MomentImage image = generateMomentImage(s.volume, viewOf(s), small(100, 0.f));
  const int x = 20, y = 16, n = 400;
  const std::vector<float> truth = sampleRay(s.volume, image, x, y, n);
  double errMese = 0.0, errFourier = 0.0;
  const std::vector<float> mese = reconstructRay(image, x, y, n, MomentReconstruction::BoundedMese);
  const std::vector<float> fourier = reconstructRay(image, x, y, n, MomentReconstruction::Fourier);
  for (int k = 0; k < n; ++k) {
    errMese += std::abs(mese[k] - truth[k]) / n;
    errFourier += std::abs(fourier[k] - truth[k]) / n;
    // The MESE stays within the pixel's bounds (Eq. 3 maps into (0, 1) before Eq. 5).
    const int64_t p = int64_t(y) * image.width + x;
    EXPECT_GE(mese[k], image.lower[p]);
    EXPECT_LE(mese[k], image.upper[p]);
  }
  EXPECT_LT(errMese, 0.02);
  EXPECT_LT(errFourier, 0.03);
}

TEST(MomentImage, RendersLikeTheVolumeWithANewTransferFunction) {
  for (const char* name : {"marschner-lobb", "shepp-logan"}) {
    const BuiltinScene s = scene(name, 48);
    const Camera cam = viewOf(s);
    MomentImageSettings settings;
    settings.width = 64;
    settings.height = 64;
    const MomentImage image = generateMomentImage(s.volume, cam, settings);
    // A transfer function the image was not made with: the scene's own and a generic ramp.
    for (const TransferFunction& tf :
         {s.transferFunction,
          TransferFunction::preset("generic", s.volume.valueMin, s.volume.valueMax)}) {
      const MomentRenderSettings r;
      const Image direct = renderVolumeEmissionAbsorption(s.volume, cam, 64, 64, tf, r);
      const Image mese = renderMomentImage(image, tf, r);
      MomentRenderSettings rf = r;
      rf.reconstruction = MomentReconstruction::Fourier;
      const Image fourier = renderMomentImage(image, tf, rf);
      double peak = 0.0;
      for (const glm::vec3& c : direct.pixels) peak = std::max<double>(peak, c.x + c.y + c.z);
      ASSERT_GT(peak, 0.05) << name << ": the direct image is black";
      EXPECT_GT(psnr(mese, direct), 30.0) << name << " " << tf.name;
      EXPECT_GT(psnr(fourier, direct), 25.0) << name << " " << tf.name;
    }
  }
}

// The renderer's lanes path (kMomentLanes samples side by side) against its per-sample reference:
// the same images to float round-off, MESE and Fourier, pre-integrated and midpoint, and with a
// transfer function dense enough that rays turn opaque part-way through a block of samples.
// The densities themselves agree to float round-off (the lanes tests above); pre-integration
// then amplifies their round-off: its lookup (F(x_b) - F(x_f)) / (x_b - x_f) divides by density
// steps down to 1e-3, so its slope reaches ~1e3 times the transfer function's, and a density
// difference of one float ulp (~1e-7) moves a sample's opacity by up to ~1e-4. The CUDA build's
// different inlining showed 1.1e-4 (Fourier, Shepp-Logan); the bound allows that conditioning.
// A lane mixed up with another moves pixels by the image's own contrast (>= 0.02 here).
TEST(MomentImage, TheLaneRenderEqualsThePerSampleReference) {
  constexpr float kPreintegratedBound = 1e-3f;
  for (const char* name : {"marschner-lobb", "shepp-logan"}) {
    const BuiltinScene s = scene(name, 48);
    const Camera cam = viewOf(s);
    MomentImageSettings settings;
    settings.width = 48;
    settings.height = 40;
    settings.errorThreshold = 0.005f;  // per-pixel counts vary, as they do in practice
    const MomentImage image = generateMomentImage(s.volume, cam, settings);
    TransferFunction dense = s.transferFunction;
    dense.unitDistance = 0.02f * s.volume.grid().minSpacing();
    for (int t = 0; t < 2; ++t)
      for (MomentReconstruction rec :
           {MomentReconstruction::BoundedMese, MomentReconstruction::Fourier})
        for (bool pre : {true, false}) {
          MomentRenderSettings r;
          r.reconstruction = rec;
          r.preintegrate = pre;
          const TransferFunction& tf = t == 0 ? s.transferFunction : dense;
          const Image lanes = renderMomentImage(image, tf, r);
          r.perSampleReference = true;
          const Image reference = renderMomentImage(image, tf, r);
          float worst = 0.f, brightest = 0.f;
          for (size_t p = 0; p < lanes.pixels.size(); ++p) {
            const glm::vec3 d = glm::abs(lanes.pixels[p] - reference.pixels[p]);
            worst = std::max({worst, d.x, d.y, d.z});
            brightest = std::max(brightest, reference.pixels[p].x);
          }
          EXPECT_LE(worst, pre ? kPreintegratedBound : 1e-5f)
              << name << " " << toString(rec) << " pre " << pre << " "
              << (t == 1 ? "dense" : "scene");
          EXPECT_GT(brightest, 0.02f) << name << ": a black image compares trivially";
        }
  }
}

// A volume whose density ramps from 0 to 1 along x, seen along x.
Volume rampVolume(int n) {
  Volume v;
  v.name = "ramp";
  GridSpec g;
  g.dims = glm::ivec3(n, 8, 8);
  v.normalized = Field3D("ramp", g, Precision::FP32);
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < n; ++i) v.normalized.set(g.linearIndex(i, j, k), float(i) / float(n - 1));
  return v;
}

TEST(MomentImage, PreintegrationCatchesAThinFeatureAtACoarseStep) {
  const int n = 64;
  const Volume v = rampVolume(n);
  Camera cam;
  cam.eye = glm::vec3(-100.f, 3.5f, 3.5f);
  cam.target = glm::vec3(30.f, 3.5f, 3.5f);
  cam.fovYDegrees = 1.f;
  // A feature 0.004 wide in value (a quarter voxel of the ramp): opaque white at 0.5.
  TransferFunction tf;
  tf.opacity = {{0.0, 0.f}, {0.498, 0.f}, {0.5, 0.5f}, {0.502, 0.f}, {1.0, 0.f}};
  tf.color = {{0.0, glm::vec3(1.f)}, {1.0, glm::vec3(1.f)}};
  tf.validate();
  MomentRenderSettings fine;
  fine.stepVoxels = 0.02f;
  fine.preintegrate = false;
  MomentRenderSettings coarse = fine;
  coarse.stepVoxels = 3.f;
  MomentRenderSettings coarsePre = coarse;
  coarsePre.preintegrate = true;
  const float ref = renderVolumeEmissionAbsorption(v, cam, 5, 5, tf, fine).at(2, 2).x;
  const float pre = renderVolumeEmissionAbsorption(v, cam, 5, 5, tf, coarsePre).at(2, 2).x;
  const float mid = renderVolumeEmissionAbsorption(v, cam, 5, 5, tf, coarse).at(2, 2).x;
  ASSERT_GT(ref, 0.002f);
  EXPECT_NEAR(pre, ref, 0.05f * ref);
  EXPECT_GT(std::abs(mid - ref), 0.5f * ref);  // midpoint samples miss or overweight it
}

TEST(PSquare, EstimatesAQuantileOfALongSequenceAndIsExactForFewValues) {
  // Exact order statistics up to five values.
  PSquare few(0.5f);
  for (float v : {5.f, 1.f, 3.f}) few.add(v);
  EXPECT_EQ(few.value(), 3.f);
  // A deterministic pseudo-random sequence: the estimate against the sorted values.
  for (float p : {0.5f, 0.9f, 0.95f}) {
    PSquare q(p);
    std::vector<float> values;
    uint32_t state = 12345u;
    for (int i = 0; i < 5000; ++i) {
      state = state * 1664525u + 1013904223u;
      const float u = float(state >> 8) / float(1u << 24);
      const float v = u * u;  // skewed, like errors
      values.push_back(v);
      q.add(v);
    }
    std::sort(values.begin(), values.end());
    const float exact = values[size_t(p * float(values.size() - 1))];
    EXPECT_NEAR(q.value(), exact, 0.01f) << "p=" << p;
  }
}

TEST(MomentImage, TheUncertaintyIsTheErrorQuantileAlongTheRayAndFallsWithMoreMoments) {
  const BuiltinScene s = scene();
  MomentImageSettings settings = small(60, 0.1f);
  settings.uncertaintyQuantile = 0.9f;
  const MomentImage coarse = generateMomentImage(s.volume, viewOf(s), settings);
  settings.errorThreshold = 0.f;
  const MomentImage fine = generateMomentImage(s.volume, viewOf(s), settings);
  ASSERT_EQ(coarse.uncertainty.size(), coarse.pixelCount());
  double meanCoarse = 0.0, meanFine = 0.0;
  int hit = 0;
  for (size_t p = 0; p < coarse.pixelCount(); ++p) {
    if (coarse.counts[p] == 0) {
      EXPECT_EQ(coarse.uncertainty[p], 0.f);
      continue;
    }
    meanCoarse += coarse.uncertainty[p];
    meanFine += fine.uncertainty[p];
    ++hit;
  }
  EXPECT_LT(meanFine, meanCoarse);
  // One pixel against the exact quantile of its reconstruction's errors.
  const int x = 20, y = 16;
  const int64_t p = int64_t(y) * coarse.width + x;
  const std::vector<uint64_t> offsets = coarse.offsets();
  const MomentRay r = momentRay(
      FrustumMap(FrustumGrid::forCamera(coarse.camera, coarse.width, coarse.height,
                                        coarse.grid.worldBounds(), 1, coarse.grid.minSpacing())),
      GridMap(coarse.grid), p);
  const int n = momentSampleCount(r, coarse.stepVoxels * coarse.grid.minSpacing());
  const std::vector<float> truth = sampleRay(s.volume, coarse, x, y, n);
  const std::vector<float> rec = reconstructRay(coarse, x, y, n, MomentReconstruction::BoundedMese);
  std::vector<float> errors;
  for (int k = 0; k < n; ++k) errors.push_back(std::abs(rec[k] - truth[k]));
  std::sort(errors.begin(), errors.end());
  const float exact = errors[size_t(0.9 * (n - 1))];
  EXPECT_NEAR(coarse.uncertainty[p], exact, 0.2f * exact + 1e-3f);
  const Image heat = renderMomentUncertainty(coarse);
  EXPECT_EQ(heat.width, coarse.width);
  EXPECT_THROW(renderMomentUncertainty(generateMomentImage(s.volume, viewOf(s), small(10))), Error);
}

// --- the .vmi file -------------------------------------------------------------------------

std::string tmpPath(const char* name) {
  std::filesystem::create_directories(VISOPT_TEST_TMP);
  return std::string(VISOPT_TEST_TMP) + "/" + name;
}

std::vector<char> bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::string& path, const std::vector<char>& b) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(b.data(), std::streamsize(b.size()));
}

std::string refusal(const std::string& path) {
  try {
    readMomentImage(path);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput) << e.what();
    return e.what();
  }
  return "";
}

TEST(MomentImageFile, RoundTripsBitForBit) {
  const BuiltinScene s = scene();
  MomentImageSettings settings = small(40, 0.01f);
  settings.uncertaintyQuantile = 0.95f;
  const MomentImage image = generateMomentImage(s.volume, viewOf(s), settings);
  const std::string path = tmpPath("round.vmi");
  writeMomentImage(image, path);
  const MomentImage back = readMomentImage(path);
  EXPECT_EQ(back.width, image.width);
  EXPECT_EQ(back.height, image.height);
  EXPECT_EQ(back.order, image.order);
  EXPECT_EQ(back.camera, image.camera);
  EXPECT_EQ(back.grid, image.grid);
  EXPECT_EQ(back.valueMin, image.valueMin);
  EXPECT_EQ(back.counts, image.counts);
  EXPECT_EQ(back.lower, image.lower);
  EXPECT_EQ(back.upper, image.upper);
  EXPECT_EQ(back.moments, image.moments);
  EXPECT_EQ(back.uncertaintyQuantile, 0.95f);
  EXPECT_EQ(back.uncertainty, image.uncertainty);
}

TEST(MomentImageFile, BrokenFilesAreRefusedNamingTheFileAndTheProblem) {
  const BuiltinScene s = scene();
  const MomentImage image = generateMomentImage(s.volume, viewOf(s), small(20, 0.01f));
  const std::string good = tmpPath("good.vmi"), bad = tmpPath("bad.vmi");
  writeMomentImage(image, good);
  const std::vector<char> bytes = bytesOf(good);

  // Truncated anywhere.
  for (size_t cut : {size_t(3), size_t(20), bytes.size() / 2, bytes.size() - 1}) {
    writeBytes(bad, std::vector<char>(bytes.begin(), bytes.begin() + long(cut)));
    const std::string msg = refusal(bad);
    EXPECT_NE(msg.find(bad), std::string::npos) << msg;
    EXPECT_NE(msg.find("truncated"), std::string::npos) << "cut " << cut << ": " << msg;
  }
  // A flipped byte in each block's payload: the checksum catches it.
  for (size_t at : {size_t(40), bytes.size() / 2, bytes.size() - 3}) {
    std::vector<char> b = bytes;
    b[at] ^= 0x10;
    writeBytes(bad, b);
    EXPECT_NE(refusal(bad).find("corrupt"), std::string::npos) << "byte " << at;
  }
  // Wrong magic and version.
  {
    std::vector<char> b = bytes;
    b[0] = 'X';
    writeBytes(bad, b);
    EXPECT_NE(refusal(bad).find("magic"), std::string::npos);
    b = bytes;
    b[8] = 7;
    writeBytes(bad, b);
    EXPECT_NE(refusal(bad).find("version 7"), std::string::npos);
  }
  // A header that claims more pixels than the file holds, with a valid checksum: HEAD's payload
  // starts at byte 32 (magic 8, version 4, block count 4, tag 4, length 8, CRC 4) with the width.
  {
    std::vector<char> b = bytes;
    const int32_t width = image.width * 2;
    std::memcpy(b.data() + 32, &width, 4);
    uint64_t length = 0;
    std::memcpy(&length, b.data() + 20, 8);
    const uint32_t crc = uint32_t(
        crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(b.data() + 32), uInt(length)));
    std::memcpy(b.data() + 28, &crc, 4);
    writeBytes(bad, b);
    EXPECT_NE(refusal(bad).find("the header says"), std::string::npos) << refusal(bad);
    MomentImage shortMoments = image;
    shortMoments.moments.pop_back();
    writeMomentImage(shortMoments, bad);
    EXPECT_NE(refusal(bad).find("the counts add up to"), std::string::npos);
    MomentImage tooMany = image;
    tooMany.counts[0] = uint8_t(tooMany.order + 5);
    writeMomentImage(tooMany, bad);
    EXPECT_NE(refusal(bad).find("above the order"), std::string::npos);
  }
  EXPECT_NE(refusal(tmpPath("does-not-exist.vmi")).find("not found"), std::string::npos);
}

}  // namespace
}  // namespace visopt
