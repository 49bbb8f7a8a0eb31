// Built-in scenes: every scene builds, is deterministic and finite; Shepp–Logan and
// Marschner–Lobb match their analytic definitions; every scene's importance field is a sane
// soft indicator of its structures (for Shepp–Logan the tumours and nothing of the shell), and
// the default view sees what is important through something opaque.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/field_view.h"
#include "scenes/scene_common.h"
#include "scenes/shepp_logan.h"
#include "visopt/camera.h"
#include "visopt/error.h"
#include "visopt/memory_ledger.h"
#include "visopt/scenes.h"

using namespace visopt;

namespace {

float importanceAt(const std::vector<glm::vec2>& curve, float t) {
  if (t <= curve.front().x) return curve.front().y;
  for (size_t i = 1; i < curve.size(); ++i)
    if (t < curve[i].x) {
      const float f = (t - curve[i - 1].x) / (curve[i].x - curve[i - 1].x);
      return curve[i - 1].y + f * (curve[i].y - curve[i - 1].y);
    }
  return curve.back().y;
}

// Independent implementation of the Marschner–Lobb signal (fM = 6, alpha = 0.25).
double marschnerLobbReference(double x, double y, double z) {
  const double pi = std::acos(-1.0);
  const double r = std::sqrt(x * x + y * y);
  const double rhoR = std::cos(2.0 * pi * 6.0 * std::cos(pi * r / 2.0));
  return (1.0 - std::sin(pi * z / 2.0) + 0.25 * (1.0 + rhoR)) / (2.0 * 1.25);
}

// Transmittance along the segment a -> b (world units) through the scene's TF.
double transmittance(const BuiltinScene& scene, glm::vec3 a, glm::vec3 b, float ds = 0.05f) {
  const FieldView view(scene.volume.normalized);
  const GridSpec& g = scene.volume.grid();
  const float len = glm::length(b - a);
  const int steps = int(std::ceil(len / ds));
  double tau = 0.0;
  for (int s = 0; s < steps; ++s) {
    const glm::vec3 p = a + (b - a) * ((float(s) + 0.5f) / float(steps));
    const float t = view.sample(g.worldToIndex(p));
    tau += scene.transferFunction.extinctionAt(scene.volume.toValue(t), g.minSpacing()) *
           (len / float(steps));
  }
  return std::exp(-tau);
}

// Mean over the important voxels (g > 0.5, weighted by g) of the transmittance from the default
// eye to the voxel through the scene's TF, counting only material that is not itself important
// (g < 0.05), so it measures how much of the important structure something else hides.
double meanOcclusionTransmittance(const BuiltinScene& scene) {
  const FieldView vol(scene.volume.normalized), imp(scene.importance);
  const GridSpec& g = scene.volume.grid();
  const Camera cam = Camera::orbitBounds(g.worldBounds(), scene.azimuthDeg, scene.elevationDeg,
                                         scene.distanceInRadii);
  const float ds = 0.5f * g.minSpacing();
  double sumT = 0.0, sumW = 0.0;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const float weight = imp.at(i, j, k);
        if (weight <= 0.5f) continue;
        const glm::vec3 target = g.indexToWorld(glm::vec3(i, j, k));
        const float len = glm::length(target - cam.eye);
        const int steps = int(std::ceil(len / ds));
        double tau = 0.0;
        for (int s = 0; s < steps; ++s) {
          const glm::vec3 p = cam.eye + (target - cam.eye) * ((float(s) + 0.5f) / float(steps));
          const glm::vec3 idx = g.worldToIndex(p);
          if (glm::any(glm::lessThan(idx, glm::vec3(0.f))) ||
              glm::any(glm::greaterThan(idx, glm::vec3(g.dims - 1))))
            continue;
          if (imp.sample(idx) >= 0.05f) continue;
          tau += scene.transferFunction.extinctionAt(scene.volume.toValue(vol.sample(idx)),
                                                     g.minSpacing()) *
                 (len / float(steps));
        }
        sumT += weight * std::exp(-tau);
        sumW += weight;
      }
  return sumW > 0.0 ? sumT / sumW : 1.0;
}

}  // namespace

TEST(Scenes, ListsTheScenesAndTheDefault) {
  const auto scenes = builtinScenes();
  EXPECT_EQ(defaultSceneName(), "shepp-logan");
  std::vector<std::string> names;
  for (const auto& s : scenes) {
    names.push_back(s.name);
    EXPECT_FALSE(s.description.empty());
    EXPECT_EQ(s.description.find('\n'), std::string::npos);
  }
  for (const char* expected : {"shepp-logan", "marschner-lobb", "earth-mantle", "mixer"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
}

TEST(Scenes, RejectsBadNamesAndResolutions) {
  for (int res : {-1, 0, 1, 1025}) {
    try {
      makeBuiltinScene("shepp-logan", res, Precision::FP32);
      FAIL() << res;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage);
    }
  }
  try {
    makeBuiltinScene("no-such-scene", 32, Precision::FP32);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
    EXPECT_NE(std::string(e.what()).find("shepp-logan"), std::string::npos);  // lists the names
  }
  EXPECT_NO_THROW(makeBuiltinScene("shepp-logan", 2, Precision::FP32));
}

TEST(Scenes, EverySceneBuildsSaneAndDeterministic) {
  for (const auto& desc : builtinScenes()) {
    for (int res : {32, 64}) {
      SCOPED_TRACE(desc.name + " @ " + std::to_string(res));
      const BuiltinScene a = makeBuiltinScene(desc.name, res, Precision::FP32);
      const BuiltinScene b = makeBuiltinScene(desc.name, res, Precision::FP32);
      const Volume& v = a.volume;
      const GridSpec& g = v.grid();
      EXPECT_EQ(v.sourcePath, "builtin:" + desc.name);
      EXPECT_EQ(v.normalized.name(), "volume");
      EXPECT_EQ(g.dims, glm::ivec3(res));
      EXPECT_NEAR(g.extent().x, 200.f, 1e-3f);
      EXPECT_NEAR(glm::length(g.worldBounds().center()), 0.f, 1e-3f);
      EXPECT_EQ(g.direction, glm::mat3(1.f));
      EXPECT_LT(v.valueMin, v.valueMax);
      ASSERT_EQ(a.volume.normalized.size(), b.volume.normalized.size());
      float lo = 1e30f, hi = -1e30f;
      size_t important = 0, differing = 0;
      for (size_t i = 0; i < v.normalized.size(); ++i) {
        const float t = v.normalized.get(i);
        ASSERT_TRUE(std::isfinite(t));
        ASSERT_GE(t, 0.f);
        ASSERT_LE(t, 1.f);
        lo = std::min(lo, t);
        hi = std::max(hi, t);
        if (importanceAt(a.importanceCurve, t) > 0.5f) ++important;
        if (t != b.volume.normalized.get(i)) ++differing;
      }
      EXPECT_EQ(differing, 0u);
      EXPECT_GT(hi - lo, 0.5f);  // uses its range
      // The importance marks something, but not most of the volume.
      EXPECT_GT(important, 0u);
      EXPECT_LT(double(important), 0.3 * double(v.normalized.size()));
      // Transfer function and view.
      TransferFunction tf = a.transferFunction;
      EXPECT_NO_THROW(tf.validate(desc.name));
      const TransferTable table = tf.bake(v.valueMin, v.valueMax, g.minSpacing());
      EXPECT_GT(table.maxExtinction, 0.f);
      EXPECT_GE(a.distanceInRadii, 2.f);
      EXPECT_LE(a.distanceInRadii, 4.f);
      ASSERT_GE(a.importanceCurve.size(), 2u);
      for (size_t i = 0; i < a.importanceCurve.size(); ++i) {
        const glm::vec2 p = a.importanceCurve[i];
        EXPECT_GE(p.x, 0.f);
        EXPECT_LE(p.x, 1.f);
        EXPECT_GE(p.y, 0.f);
        EXPECT_LE(p.y, 1.f);
        if (i) {
          EXPECT_GE(p.x, a.importanceCurve[i - 1].x);
        }
      }
    }
  }
}

TEST(Scenes, EverySceneHasASaneDeterministicImportanceField) {
  for (const auto& desc : builtinScenes()) {
    for (int res : {32, 64}) {
      SCOPED_TRACE(desc.name + " @ " + std::to_string(res));
      const BuiltinScene a = makeBuiltinScene(desc.name, res, Precision::FP32);
      const BuiltinScene b = makeBuiltinScene(desc.name, res, Precision::FP32);
      const Field3D& g = a.importance;
      ASSERT_FALSE(g.empty());
      EXPECT_EQ(g.name(), "importance");
      EXPECT_EQ(g.grid(), a.volume.grid());
      EXPECT_EQ(g.precision(), Precision::FP32);
      ASSERT_EQ(g.size(), b.importance.size());
      size_t marked = 0, differing = 0;
      for (size_t i = 0; i < g.size(); ++i) {
        const float v = g.get(i);
        ASSERT_TRUE(std::isfinite(v)) << i;
        ASSERT_GE(v, 0.f) << i;
        ASSERT_LE(v, 1.f) << i;
        if (v > 0.5f) ++marked;
        if (v != b.importance.get(i)) ++differing;
      }
      EXPECT_EQ(differing, 0u);
      const double fraction = double(marked) / double(g.size());
      EXPECT_GT(fraction, 0.0005);
      EXPECT_LT(fraction, 0.3);
    }
  }
}

TEST(Scenes, ImportanceIsStoredLikeTheVolumeAndListedInTheLedger) {
  for (const auto& desc : builtinScenes()) {
    SCOPED_TRACE(desc.name);
    MemoryLedger ledger;
    {
      const BuiltinScene scene = makeBuiltinScene(desc.name, 16, Precision::FP16, &ledger);
      EXPECT_EQ(scene.importance.precision(), Precision::FP16);
      EXPECT_EQ(scene.importance.grid(), scene.volume.grid());
      bool listed = false;
      for (const LedgerEntry& e : ledger.entries())
        if (e.name == "importance") {
          listed = true;
          EXPECT_EQ(e.bytes, scene.importance.bytes());
          EXPECT_EQ(e.precision, "fp16");
        }
      EXPECT_TRUE(listed);
      const BuiltinScene full = makeBuiltinScene(desc.name, 16, Precision::FP32);
      for (size_t i = 0; i < full.importance.size(); ++i)
        ASSERT_NEAR(full.importance.get(i), scene.importance.get(i), 1e-3f);
    }
    EXPECT_TRUE(ledger.entries().empty());  // freed with the scene
  }
}

TEST(Scenes, SheppLoganImportanceIsTheTumoursAndNothingOfTheShell) {
  const auto& table = scenes::sheppLoganEllipsoids();
  const scenes::SoftEllipsoid outer(table[0].center, table[0].semiAxes, table[0].angleDeg);
  const scenes::SoftEllipsoid brain(table[1].center, table[1].semiAxes, table[1].angleDeg);
  for (int res : {32, 64, 128}) {
    SCOPED_TRACE(res);
    const BuiltinScene scene = makeBuiltinScene("shepp-logan", res, Precision::FP32);
    const GridSpec& g = scene.importance.grid();
    const FieldView imp(scene.importance);
    const auto at = [&](glm::vec3 normalised) {
      return imp.sample(g.worldToIndex(normalised * 100.f));
    };
    // ~1 at every tumour's centre (rows 4..9 of the table), even the sub-voxel ones.
    for (size_t n = 4; n < table.size(); ++n) EXPECT_GT(at(table[n].center), 0.95f) << n;
    // 0 in the ventricles, the brain away from the tumours and the air.
    EXPECT_EQ(at(table[2].center), 0.f);
    EXPECT_EQ(at(table[3].center), 0.f);
    EXPECT_EQ(at({0.f, -0.3f, -0.3f}), 0.f);
    EXPECT_EQ(at({0.f, 0.f, 0.95f}), 0.f);
    // Exactly 0 at every voxel of the shell, its faces and outside it: all voxels within two
    // voxels of the brain's surface or beyond (the value-based curve marks both faces there).
    const float w = scenes::edgeHalfWidth(g);
    size_t shellVoxels = 0;
    for (int k = 0; k < g.dims.z; ++k)
      for (int j = 0; j < g.dims.y; ++j)
        for (int i = 0; i < g.dims.x; ++i) {
          const glm::vec3 p = g.indexToWorld(glm::vec3(i, j, k)) / 100.f;
          if (brain.distance(p) <= -2.f * w) continue;
          if (outer.distance(p) < 2.f * w) ++shellVoxels;
          ASSERT_EQ(imp.at(i, j, k), 0.f) << i << " " << j << " " << k;
        }
    EXPECT_GT(shellVoxels, 0u);
    // Along rays from the centre outward through the shell (interpolated between voxels): 0 from
    // the shell's inner face to beyond its outer face, where the value crosses 0.3 twice.
    const std::vector<glm::vec3> dirs = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},  {0, -1, 0},
                                         {0, 0, 1},  {0, 0, -1}, {1, 1, 1},  {-1, 1, -1},
                                         {1, -1, 1}, {0, 1, -1}, {1, -2, 0}, {-2, 0, 1}};
    for (glm::vec3 dir : dirs) {
      dir = glm::normalize(dir);
      int shellSamples = 0;
      for (float t = 0.f; t < 1.f; t += 0.002f) {
        const glm::vec3 p = t * dir;
        if (brain.distance(p) < -0.25f * w || outer.distance(p) > 2.f * w) continue;
        ++shellSamples;
        ASSERT_EQ(at(p), 0.f) << "dir " << dir.x << " " << dir.y << " " << dir.z << " t " << t;
      }
      EXPECT_GT(shellSamples, 10);
    }
  }
}

// From 48^3 up (the CLI's default is 128^3); at 32^3 a voxel (6.5 mm) is wider than the mixer's
// wall and the mantle's crust, whose smoothed profiles then no longer reach opaque values.
TEST(Scenes, DefaultViewsSeeTheImportantThroughSomethingOpaque) {
  for (const auto& desc : builtinScenes())
    for (int res : {48, 64, 128}) {
      // ct-head's occluder is its skin, a context surface (in the volume the preset's skin band
      // is a partial-volume layer, as in a real CT): test_ct_head_scene checks that it hides.
      if (desc.name == "ct-head") continue;
      // level-set-cases shows an important object in front of its context on purpose (paper
      // 000's Fig. 3, left); test_level_set_cases_scene checks what hides what there.
      if (desc.name == "level-set-cases") continue;
      SCOPED_TRACE(desc.name + " @ " + std::to_string(res));
      const BuiltinScene scene = makeBuiltinScene(desc.name, res, Precision::FP32);
      EXPECT_LT(meanOcclusionTransmittance(scene), 0.3);
    }
}

TEST(Scenes, Fp16StorageMatchesFp32) {
  MemoryLedger* ledger = nullptr;
  const BuiltinScene full = makeBuiltinScene("earth-mantle", 32, Precision::FP32, ledger);
  const BuiltinScene half = makeBuiltinScene("earth-mantle", 32, Precision::FP16, ledger);
  EXPECT_EQ(half.volume.normalized.precision(), Precision::FP16);
  for (size_t i = 0; i < full.volume.normalized.size(); ++i)
    ASSERT_NEAR(full.volume.normalized.get(i), half.volume.normalized.get(i), 1e-3f);
}

TEST(Scenes, SheppLoganMatchesTheAnalyticPhantom) {
  const BuiltinScene scene = makeBuiltinScene("shepp-logan", 64, Precision::FP32);
  const Volume& vol = scene.volume;
  const GridSpec& g = vol.grid();
  const FieldView view(vol.normalized);
  const auto& table = scenes::sheppLoganEllipsoids();
  ASSERT_EQ(table.size(), 10u);
  const auto valueAt = [&](glm::vec3 normalised) {
    return vol.toValue(view.sample(g.worldToIndex(normalised * 100.f)));
  };
  // Hand sums of the modified densities (1, -0.8, -0.2 ventricles, +0.1 tumours).
  EXPECT_NEAR(valueAt(table[4].center), 1.0 - 0.8 + 0.1, 1e-5);  // large tumour
  EXPECT_NEAR(valueAt(table[3].center), 1.0 - 0.8 - 0.2, 1e-5);  // left ventricle
  EXPECT_NEAR(valueAt(table[2].center), 1.0 - 0.8 - 0.2, 1e-5);  // right ventricle
  EXPECT_NEAR(valueAt({0.f, 0.f, 0.f}), 1.0 - 0.8, 1e-5);        // brain
  EXPECT_NEAR(valueAt({0.f, -0.3f, 0.45f}), 1.0 - 0.8, 1e-5);
  EXPECT_NEAR(valueAt({0.f, 0.f, 0.95f}), 0.0, 1e-5);  // air above the head
  EXPECT_NEAR(scenes::sheppLoganDensity(table[5].center), 0.3f, 1e-6);
  // Every voxel clear of all ellipsoid edges holds exactly the analytic sum.
  const float w = scenes::edgeHalfWidth(g);
  size_t checked = 0;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::vec3 p = g.indexToWorld(glm::vec3(i, j, k)) / 100.f;
        bool clear = true;
        for (const auto& e : table)
          clear = clear &&
                  std::abs(scenes::SoftEllipsoid(e.center, e.semiAxes, e.angleDeg).distance(p)) >
                      1.01f * w;
        if (!clear) continue;
        ++checked;
        ASSERT_NEAR(vol.toValue(vol.normalized.get(g.linearIndex(i, j, k))),
                    scenes::sheppLoganDensity(p), 1e-5)
            << i << " " << j << " " << k;
      }
  EXPECT_GT(checked, size_t(0.8 * double(g.voxelCount())));
}

TEST(Scenes, MarschnerLobbEqualsTheFormulaAtVoxelCentres) {
  for (int res : {32, 41}) {
    const BuiltinScene scene = makeBuiltinScene("marschner-lobb", res, Precision::FP32);
    const Volume& vol = scene.volume;
    const GridSpec& g = vol.grid();
    EXPECT_EQ(vol.valueMin, 0.0);
    EXPECT_EQ(vol.valueMax, 1.0);
    double maxErr = 0.0;
    for (int k = 0; k < g.dims.z; ++k)
      for (int j = 0; j < g.dims.y; ++j)
        for (int i = 0; i < g.dims.x; ++i) {
          // Voxel centres span [-1, 1]^3 exactly.
          const double x = -1.0 + 2.0 * i / (res - 1), y = -1.0 + 2.0 * j / (res - 1),
                       z = -1.0 + 2.0 * k / (res - 1);
          const double v = vol.toValue(vol.normalized.get(g.linearIndex(i, j, k)));
          maxErr = std::max(maxErr, std::abs(v - marschnerLobbReference(x, y, z)));
        }
    EXPECT_LT(maxErr, 2e-6) << res;
  }
}

TEST(Scenes, DefaultSceneHidesTheImportantBehindAnOpaqueShell) {
  for (int res : {64, 128}) {
    SCOPED_TRACE(res);
    const BuiltinScene scene = makeBuiltinScene(defaultSceneName(), res, Precision::FP32);
    const auto& table = scenes::sheppLoganEllipsoids();
    // The tumours are important.
    const float tumour = scene.volume.toNormalized(0.3);
    EXPECT_GT(importanceAt(scene.importanceCurve, tumour), 0.9f);
    EXPECT_LT(importanceAt(scene.importanceCurve, scene.volume.toNormalized(0.2)), 0.1f);
    EXPECT_LT(importanceAt(scene.importanceCurve, scene.volume.toNormalized(1.0)), 0.1f);
    // The shell alone, crossed along each axis from outside to just inside its inner ellipsoid,
    // lets less than 30% of the light through.
    const glm::vec3 outer = table[0].semiAxes, inner = table[1].semiAxes;
    const glm::vec3 innerCenter = table[1].center;
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {-1.f, 1.f}) {
        glm::vec3 a(0.f), b(0.f);
        a[axis] = sign * 1.f;
        b[axis] = innerCenter[axis] + sign * (inner[axis] - 0.04f);
        ASSERT_GT(std::abs(b[axis]), 0.5f * outer[axis]);
        const double T = transmittance(scene, a * 100.f, b * 100.f);
        EXPECT_LT(T, 0.3) << "axis " << axis << " sign " << sign;
      }
    // Behind the shell the brain is a thin haze (here 14 cm of it, clear of the tumours), so
    // the hidden tumours would show without the shell.
    const double insideOnly =
        transmittance(scene, glm::vec3(0.f, -30.f, -70.f), glm::vec3(0.f, -30.f, 70.f));
    EXPECT_GT(insideOnly, 0.5);
  }
}

TEST(Scenes, GeneratesQuickly) {
  const auto start = std::chrono::steady_clock::now();
  const BuiltinScene scene = makeBuiltinScene("shepp-logan", 128, Precision::FP16);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(scene.volume.normalized.size(), size_t(128) * 128 * 128);
  EXPECT_LT(s, 10.0);  // generous; 256^3 takes a few seconds on 2 cores
}
