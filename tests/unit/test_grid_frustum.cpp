// Grid geometry, frustum mappings g_V / g_L (Himmler & Günther 2026, Eqs. 4-5) against
// hand-computed values, and the round trip g^-1(g(x)) = x.
#include <cmath>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "visopt/camera.h"
#include "visopt/error.h"
#include "visopt/frustum.h"
#include "visopt/grid.h"

using namespace visopt;

namespace {
void expectNear(glm::vec3 a, glm::vec3 b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}
}  // namespace

TEST(GridSpec, AnisotropicIndexToWorldByHand) {
  GridSpec g;
  g.dims = {10, 20, 30};
  g.spacing = {0.5f, 2.f, 3.f};
  g.origin = {1.f, -2.f, 4.f};
  expectNear(g.indexToWorld({0, 0, 0}), {1.f, -2.f, 4.f}, 1e-6f);
  expectNear(g.indexToWorld({2, 3, 4}), {2.f, 4.f, 16.f}, 1e-6f);
  expectNear(g.worldToIndex({2.f, 4.f, 16.f}), {2, 3, 4}, 1e-5f);
  EXPECT_EQ(g.voxelCount(), 6000u);
  EXPECT_EQ(g.linearIndex(1, 2, 3), size_t((3 * 20 + 2) * 10 + 1));
  expectNear(g.extent(), {4.5f, 38.f, 87.f}, 1e-5f);
}

TEST(GridSpec, OrientationRotatesAxes) {
  GridSpec g;
  g.dims = {4, 4, 4};
  g.spacing = {1.f, 2.f, 3.f};
  // i along world +y, j along world -x, k along +z.
  g.direction = glm::mat3(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1));
  expectNear(g.indexToWorld({1, 1, 1}), {-2.f, 1.f, 3.f}, 1e-6f);
  expectNear(g.worldToIndex({-2.f, 1.f, 3.f}), {1, 1, 1}, 1e-6f);
  Bounds b = g.worldBounds();
  expectNear(b.lo, {-6.f, 0.f, 0.f}, 1e-6f);
  expectNear(b.hi, {0.f, 3.f, 9.f}, 1e-6f);
}

TEST(Camera, OrbitConventions) {
  Camera c = Camera::orbit({0, 0, 0}, 0.f, 0.f, 5.f);
  expectNear(c.eye, {0.f, -5.f, 0.f}, 1e-5f);  // az 0 looks along +y
  c = Camera::orbit({1, 1, 1}, 90.f, 0.f, 2.f);
  expectNear(c.eye, {3.f, 1.f, 1.f}, 1e-5f);
  c = Camera::orbit({0, 0, 0}, 0.f, 90.f, 2.f);
  expectNear(c.eye, {0.f, 0.f, 2.f}, 1e-5f);
  EXPECT_GT(glm::length(glm::cross(c.forward(), c.up)), 0.5f);  // up is not degenerate
}

TEST(FrustumGrid, CameraCentreRayAndDepthByHand) {
  Camera cam = Camera::orbit({0, 0, 0}, 0.f, 0.f, 10.f);  // eye (0,-10,0), looking along +y
  cam.fovYDegrees = 90.f;
  Bounds b{{-1, -1, -1}, {1, 1, 1}};
  FrustumGrid f = FrustumGrid::forCamera(cam, 4, 2, b, 8, 0.1f);
  // Depth from the box's nearest face (y = -1, 9 away) to its farthest corners (11, ±1, ±1),
  // not the bounding sphere's 10 ± sqrt(3).
  EXPECT_NEAR(f.sNear, 9.f, 1e-5f);
  EXPECT_NEAR(f.sFar, std::sqrt(123.f), 1e-5f);
  EXPECT_NEAR(f.tanHalfFovY, 1.f, 1e-6f);
  EXPECT_NEAR(f.tanHalfFovX, 2.f, 1e-6f);
  // The origin is on the optical axis, between pixel centres 1 and 2 (x) and 0 and 1 (y),
  // at distance 10, i.e. depth cell (10 - sNear)/ds - 0.5.
  glm::vec3 y = f.toGrid({0, 0, 0});
  EXPECT_NEAR(y.x, 1.5f, 1e-5f);
  EXPECT_NEAR(y.y, 0.5f, 1e-5f);
  EXPECT_NEAR(y.z, (10.f - f.sNear) / f.depthStep() - 0.5f, 1e-4f);
  // A point at 45° to the right (tan = 1 = half of tanX) lands at u = 0.5 -> px = 2.5.
  glm::vec3 p = glm::vec3(0, -10, 0) + 5.f * glm::normalize(glm::vec3(1, 1, 0));
  EXPECT_NEAR(f.toGrid(p).x, 2.5f, 1e-4f);
  EXPECT_NEAR(f.toGrid(p).y, 0.5f, 1e-4f);
}

TEST(FrustumGrid, RoundTripCameraAndLight) {
  Camera cam = Camera::orbit({0.3f, -0.2f, 0.5f}, 37.f, 21.f, 6.f);
  Bounds b{{-1, -2, -1.5f}, {1, 2, 1.5f}};
  FrustumGrid v = FrustumGrid::forCamera(cam, 64, 48, b, 0, 0.05f);
  PointLight light;
  light.position = {4.f, 3.f, 5.f};
  FrustumGrid l = FrustumGrid::forLight(light, b, {32, 32, 0}, 0.05f);
  for (FrustumGrid* f : {&v, &l}) {
    for (int n = 0; n < 200; ++n) {
      glm::vec3 x(b.lo + (b.hi - b.lo) * glm::vec3(float((n * 37) % 101) / 100.f,
                                                   float((n * 53) % 97) / 96.f,
                                                   float((n * 71) % 89) / 88.f));
      expectNear(f->toWorld(f->toGrid(x)), x, 2e-4f);
      glm::vec3 y(float(n % 30), float((n * 7) % 30), float((n * 13) % 40));
      expectNear(f->toGrid(f->toWorld(y)), y, 2e-3f);
    }
  }
}

TEST(FrustumGrid, LightFrustumContainsTheVolume) {
  Bounds b{{-1, -1, -1}, {1, 1, 1}};
  PointLight light;
  light.position = {0.f, -5.f, 2.f};
  FrustumGrid l = FrustumGrid::forLight(light, b, {16, 16, 16}, 0.1f);
  for (int c = 0; c < 8; ++c) {
    glm::vec3 corner((c & 1) ? 1.f : -1.f, (c & 2) ? 1.f : -1.f, (c & 4) ? 1.f : -1.f);
    glm::vec3 y = l.toGrid(corner);
    EXPECT_GE(y.x, -0.5f);
    EXPECT_LE(y.x, 15.5f);
    EXPECT_GE(y.y, -0.5f);
    EXPECT_LE(y.y, 15.5f);
    EXPECT_GE(y.z, -0.5f);
    EXPECT_LE(y.z, 15.5f);
  }
  // The light inside the volume still gives a usable (wide) frustum.
  light.position = {0.f, 0.f, 0.2f};
  FrustumGrid inside = FrustumGrid::forLight(light, b, {16, 16, 0}, 0.1f);
  EXPECT_TRUE(std::isfinite(inside.tanHalfFovX));
  EXPECT_GT(inside.sFar, inside.sNear);
}

// The depth range is the box's own: every point of the box lies in it (no sample of the volume is
// cut off), and it is tight at both ends (a point of the box at sNear and at sFar), from a few
// views of a flat box, and from an eye inside the box.
TEST(FrustumGrid, DepthRangeIsTheBoxsOwn) {
  const Bounds b{{-1.2f, -1.f, -0.4f}, {1.2f, 1.f, 0.4f}};
  for (const glm::vec3 angles : {glm::vec3(0, 0, 5), glm::vec3(37, 21, 4), glm::vec3(90, 80, 3),
                                 glm::vec3(200, -30, 6), glm::vec3(10, 5, 0.2f)}) {
    const Camera cam = Camera::orbit({0.1f, 0.f, 0.f}, angles.x, angles.y, angles.z);
    const FrustumGrid f = FrustumGrid::forCamera(cam, 16, 16, b, 0, 0.02f);
    float lo = 1e30f, hi = 0.f;
    for (int n = 0; n < 21 * 21 * 21; ++n) {  // a lattice of 21^3 points of the box
      const glm::vec3 t(float(n % 21) / 20.f, float((n / 21) % 21) / 20.f, float(n / 441) / 20.f);
      const float s = glm::length(b.lo + (b.hi - b.lo) * t - cam.eye);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    const bool inside =
        glm::all(glm::greaterThan(cam.eye, b.lo)) && glm::all(glm::lessThan(cam.eye, b.hi));
    EXPECT_LE(f.sNear, lo + 1e-5f) << angles.x;
    EXPECT_GE(f.sFar, hi - 1e-5f) << angles.x;
    EXPECT_NEAR(f.sFar, hi, 1e-4f) << angles.x;  // a corner is on the lattice
    if (!inside) {
      EXPECT_NEAR(f.sNear, lo, 0.15f) << angles.x;  // the lattice's point nearest the eye
    } else {
      EXPECT_LT(f.sNear, 1e-3f);
    }
    // Half a voxel per cell over the box's depth, not the sphere's 2r.
    EXPECT_EQ(f.dims.z, int(std::ceil((f.sFar - f.sNear) / 0.01f)));
  }
}

TEST(FrustumGrid, RejectsDegenerateCameras) {
  Camera cam;
  cam.eye = cam.target = {1, 1, 1};
  Bounds b{{-1, -1, -1}, {1, 1, 1}};
  EXPECT_THROW(FrustumGrid::forCamera(cam, 8, 8, b, 8, 0.1f), Error);
  cam = Camera::orbit({0, 0, 0}, 0, 0, 3);
  EXPECT_THROW(FrustumGrid::forCamera(cam, 0, 8, b, 8, 0.1f), Error);
  cam.fovYDegrees = 180.f;
  EXPECT_THROW(FrustumGrid::forCamera(cam, 8, 8, b, 8, 0.1f), Error);
}
