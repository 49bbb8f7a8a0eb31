#include "tools/picking.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <visopt/frustum.h>

namespace visopt::ws {

namespace {

// The renderer's camera frustum for the widget's image size. The bounds only set the depth
// range, which picking does not use.
std::optional<FrustumGrid> frustumOf(const ViewContext& view) {
  const int w = view.imageSize.width(), h = view.imageSize.height();
  if (w <= 0 || h <= 0) return std::nullopt;
  Bounds bounds;
  if (view.scene && view.scene->grid()) {
    bounds = view.scene->grid()->worldBounds();
  } else {
    bounds.lo = view.camera.target - glm::vec3(1.f);
    bounds.hi = view.camera.target + glm::vec3(1.f);
  }
  try {
    return FrustumGrid::forCamera(view.camera, w, h, bounds, 1, 1.f);
  } catch (...) {
    return std::nullopt;
  }
}

// Where a ray (in world units along `dir`) is inside the grid's cells [-0.5, dims - 0.5] of
// index space. Empty when it misses.
std::optional<std::pair<float, float>> clipToGrid(const GridSpec& grid, glm::vec3 origin,
                                                  glm::vec3 dir) {
  const glm::vec3 o = grid.worldToIndex(origin);
  const glm::vec3 d = (glm::transpose(grid.direction) * dir) / grid.spacing;
  float t0 = 0.f, t1 = std::numeric_limits<float>::max();
  for (int a = 0; a < 3; ++a) {
    const float lo = -0.5f, hi = static_cast<float>(grid.dims[a]) - 0.5f;
    if (std::abs(d[a]) < 1e-12f) {
      if (o[a] < lo || o[a] > hi) return std::nullopt;
      continue;
    }
    float ta = (lo - o[a]) / d[a], tb = (hi - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::nullopt;
  }
  return std::make_pair(t0, t1);
}

float sampleAt(const Field3D& field, glm::vec3 world) {
  return sampleTrilinear(field, field.grid().worldToIndex(world));
}

}  // namespace

std::optional<WorldRay> worldRay(const ViewContext& view, QPointF widgetPos) {
  const auto frustum = frustumOf(view);
  if (!frustum) return std::nullopt;
  // The renderer's pixel (px, py) has its centre at u = (px + 0.5) / width, and image row
  // `row` (0 at the top) is frustum row py = height - 1 - row.
  const float px = static_cast<float>(widgetPos.x()) - 0.5f;
  const float py =
      static_cast<float>(view.imageSize.height()) - static_cast<float>(widgetPos.y()) - 0.5f;
  WorldRay ray;
  ray.origin = frustum->eye;
  ray.direction = frustum->rayDirection(px, py);
  return ray;
}

std::optional<QPointF> projectToWidget(const ViewContext& view, glm::vec3 world) {
  const auto frustum = frustumOf(view);
  if (!frustum) return std::nullopt;
  if (glm::dot(world - frustum->eye, frustum->forward) <= 0.f) return std::nullopt;
  const glm::vec3 g = frustum->toGrid(world);
  return QPointF(static_cast<double>(g.x) + 0.5,
                 static_cast<double>(view.imageSize.height()) - static_cast<double>(g.y) - 0.5);
}

double pixelsPerWorldUnit(const ViewContext& view, glm::vec3 world) {
  const auto frustum = frustumOf(view);
  if (!frustum) return 0.0;
  const float z = glm::dot(world - frustum->eye, frustum->forward);
  if (z <= 0.f) return 0.0;
  return 0.5 * static_cast<double>(view.imageSize.height()) /
         (static_cast<double>(z) * static_cast<double>(frustum->tanHalfFovY));
}

float sampleTrilinear(const Field3D& field, glm::vec3 index) {
  if (field.empty()) return 0.f;
  const GridSpec& g = field.grid();
  const glm::vec3 hi = glm::vec3(glm::max(g.dims - 1, glm::ivec3(0)));
  const glm::vec3 p = glm::clamp(index, glm::vec3(0.f), hi);
  const glm::ivec3 i0 = glm::ivec3(glm::floor(p));
  const glm::ivec3 i1 = glm::min(i0 + 1, g.dims - 1);
  const glm::vec3 f = p - glm::vec3(i0);
  auto at = [&](int i, int j, int k) { return field.get(g.linearIndex(i, j, k)); };
  const float c00 = at(i0.x, i0.y, i0.z) * (1.f - f.x) + at(i1.x, i0.y, i0.z) * f.x;
  const float c10 = at(i0.x, i1.y, i0.z) * (1.f - f.x) + at(i1.x, i1.y, i0.z) * f.x;
  const float c01 = at(i0.x, i0.y, i1.z) * (1.f - f.x) + at(i1.x, i0.y, i1.z) * f.x;
  const float c11 = at(i0.x, i1.y, i1.z) * (1.f - f.x) + at(i1.x, i1.y, i1.z) * f.x;
  const float c0 = c00 * (1.f - f.y) + c10 * f.y;
  const float c1 = c01 * (1.f - f.y) + c11 * f.y;
  return c0 * (1.f - f.z) + c1 * f.z;
}

std::optional<glm::vec3> pickWorldPoint(const ViewContext& view, QPointF widgetPos,
                                        const PickOptions& options) {
  if (!view.scene || !view.scene->volume) return std::nullopt;
  const auto ray = worldRay(view, widgetPos);
  if (!ray) return std::nullopt;
  const Volume& volume = *view.scene->volume;
  const GridSpec& grid = volume.grid();
  const auto span = clipToGrid(grid, ray->origin, ray->direction);
  if (!span) return std::nullopt;
  const float step = std::max(options.stepFactor, 1e-3f) * grid.minSpacing();
  const auto [tEnter, tExit] = *span;
  auto point = [&](float t) { return ray->origin + t * ray->direction; };

  // Context surfaces: the first entry (phi0 from > 0 to <= 0) of any visible one.
  std::vector<const Field3D*> surfaces;
  const auto& bases = view.scene->surfaceBases;
  for (size_t i = 0; i < bases.size(); ++i) {
    const bool visible = i < view.scene->surfaces.size() ? view.scene->surfaces[i].visible : true;
    if (visible && bases[i] && !bases[i]->empty()) surfaces.push_back(bases[i].get());
  }
  if (!surfaces.empty()) {
    std::vector<float> previous(surfaces.size());
    for (size_t s = 0; s < surfaces.size(); ++s)
      previous[s] = sampleAt(*surfaces[s], point(tEnter));
    float tPrev = tEnter;
    for (float t = tEnter + step; tPrev < tExit; t += step) {
      t = std::min(t, tExit);
      float best = std::numeric_limits<float>::max();
      for (size_t s = 0; s < surfaces.size(); ++s) {
        const float phi = sampleAt(*surfaces[s], point(t));
        if (previous[s] > 0.f && phi <= 0.f) {
          // Regula falsi on [a, b] with phi(a) > 0 >= phi(b).
          float a = tPrev, b = t, fa = previous[s], fb = phi;
          float root = b;
          for (int it = 0; it < 8; ++it) {
            root = fa == fb ? b : a + (b - a) * fa / (fa - fb);
            const float fr = sampleAt(*surfaces[s], point(root));
            if (std::abs(fr) < 1e-7f) break;
            if (fr > 0.f) {
              a = root;
              fa = fr;
            } else {
              b = root;
              fb = fr;
            }
          }
          best = std::min(best, root);
        }
        previous[s] = phi;
      }
      if (best < std::numeric_limits<float>::max()) return point(best);
      tPrev = t;
    }
  }

  // The volume: the first point more opaque than the threshold.
  const TransferFunction& tf = view.scene->transferFunction;
  auto opaque = [&](float t) {
    const float scalar = sampleAt(volume.normalized, point(t));
    return tf.opacityAt(volume.toValue(scalar)) > options.opacityThreshold;
  };
  if (opaque(tEnter)) return point(tEnter);
  float tPrev = tEnter;
  for (float t = tEnter + step; tPrev < tExit; t += step) {
    t = std::min(t, tExit);
    if (opaque(t)) {
      float a = tPrev, b = t;
      for (int it = 0; it < 10; ++it) {
        const float m = 0.5f * (a + b);
        if (opaque(m))
          b = m;
        else
          a = m;
      }
      return point(b);
    }
    tPrev = t;
  }
  return std::nullopt;
}

}  // namespace visopt::ws
