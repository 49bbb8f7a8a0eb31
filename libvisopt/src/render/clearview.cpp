#include "render/clearview.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/colormap_eval.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "kernels/clearview_extract.h"
#include "kernels/ray_skip.h"
#include "render/renderer.h"
#include "visopt/error.h"
#include "visopt/exec.h"
#include "visopt/frustum.h"

namespace visopt {

namespace {

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// The sRGB encoding of a linear colour (the shaders work on display values).
glm::vec3 toDisplay(glm::vec3 c) {
  auto enc = [](float v) {
    v = std::clamp(v, 0.f, 1.f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
  };
  return {enc(c.r), enc(c.g), enc(c.b)};
}

// The empty-space flags of an isosurface (kernels/clearview_extract.h): a block is empty when
// the field's maximum over it and its 26 neighbours lies below the isovalue.
DeviceBuffer<uint8_t> emptyBlocks(const Field3D& field, float iso, glm::ivec3& blocks) {
  const DeviceBuffer<glm::vec2> range = computeBlockRange(field);  // kRaySkipBlock^3 blocks
  static_assert(kRaySkipBlock == kClearViewBlock, "ClearView reuses the renderer's block ranges");
  blocks = raySkipBlocks(field.grid().dims);
  const glm::ivec3 nb = blocks;
  const int64_t n = int64_t(nb.x) * nb.y * nb.z;
  DeviceBuffer<uint8_t> empty(static_cast<size_t>(n));
  const glm::vec2* r = range.data();
  uint8_t* out = empty.data();
  exec::parallelFor("clearview: empty blocks", n, [=] VISOPT_HD(int64_t block) {
    const int bx = int(block % nb.x), by = int((block / nb.x) % nb.y),
              bz = int(block / (int64_t(nb.x) * nb.y));
    float hi = -3.0e38f;
    for (int k = bz - 1; k <= bz + 1; ++k)
      for (int j = by - 1; j <= by + 1; ++j)
        for (int i = bx - 1; i <= bx + 1; ++i) {
          if (i < 0 || j < 0 || k < 0 || i >= nb.x || j >= nb.y || k >= nb.z) continue;
          const float h = r[(int64_t(k) * nb.y + j) * nb.x + i].y;
          hi = h > hi ? h : hi;
        }
    out[block] = hi < iso ? 1 : 0;
  });
  return empty;
}

ClearViewSurfaceField fieldOf(const ClearViewSurfaceSource& s, DeviceBuffer<uint8_t>& empty) {
  ClearViewSurfaceField f;
  f.field = FieldView(*s.field);
  f.iso = s.iso;
  f.sign = s.sign;
  if (s.sign > 0.f) {  // an isosurface; an SDF is sphere traced instead
    empty = emptyBlocks(*s.field, s.iso, f.blocks);
    f.empty = empty.data();
  }
  return f;
}

}  // namespace

size_t ClearViewContextLayer::bytes() const {
  return position.bytes() + normal.bytes() + depth.bytes() + normalDistance.bytes();
}

size_t ClearViewLayers::bytes() const {
  size_t deeper = 0;
  for (const ClearViewContextLayer& c : deeperContexts) deeper += c.bytes();
  return contextPosition.bytes() + contextNormal.bytes() + focusPosition.bytes() +
         focusNormal.bytes() + contextDepth.bytes() + focusDepth.bytes() + normalDistance.bytes() +
         deeper + volume.bytes();
}

ClearViewLayersView ClearViewLayers::view() const {
  ClearViewLayersView v;
  v.contexts[0] = {contextPosition.data(), contextNormal.data(), contextDepth.data(),
                   normalDistance.data()};
  for (size_t k = 0; k < deeperContexts.size(); ++k) {
    const ClearViewContextLayer& c = deeperContexts[k];
    v.contexts[k + 1] = {c.position.data(), c.normal.data(), c.depth.data(),
                         c.normalDistance.data()};
  }
  v.contextCount = 1 + int(deeperContexts.size());
  v.focusPosition = focusPosition.data();
  v.focusNormal = focusNormal.data();
  v.focusDepth = focusDepth.data();
  v.volume = volume.size() ? volume.data() : nullptr;
  return v;
}

void extractClearViewLayers(const Volume& volume, const DeviceBuffer<glm::vec4>& transfer,
                            const Camera& camera, int width, int height,
                            std::span<const ClearViewSurfaceSource> contexts,
                            std::span<const ClearViewSurfaceSource> foci, bool volumeLayer,
                            ClearViewLayers& out) {
  if (contexts.empty() || foci.empty() || contexts.size() > size_t(kClearViewMaxLayers) ||
      foci.size() > size_t(kClearViewMaxLayers))
    throw Error(ErrorKind::Usage, "ClearView: 1.." + std::to_string(kClearViewMaxLayers) +
                                      " context and focus layers");
  const GridSpec& grid = volume.grid();
  for (const auto* sources : {&contexts, &foci})
    for (const ClearViewSurfaceSource& s : *sources) {
      if (!s.field) throw Error(ErrorKind::Usage, "ClearView: a layer without a field");
      if (s.field->grid().dims != grid.dims)
        throw Error(ErrorKind::Usage, "ClearView: the layers' fields must be on the volume's grid");
    }
  const size_t n = size_t(width) * size_t(height);
  if (out.width != width || out.height != height || out.contextDepth.size() != n) {
    out.contextPosition = DeviceBuffer<glm::vec3>(n);
    out.contextNormal = DeviceBuffer<glm::vec3>(n);
    out.focusPosition = DeviceBuffer<glm::vec3>(n);
    out.focusNormal = DeviceBuffer<glm::vec3>(n);
    out.contextDepth = DeviceBuffer<float>(n);
    out.focusDepth = DeviceBuffer<float>(n);
    out.normalDistance = DeviceBuffer<float>(n);
    out.deeperContexts.clear();
  }
  out.deeperContexts.resize(contexts.size() - 1);
  for (ClearViewContextLayer& c : out.deeperContexts)
    if (c.depth.size() != n) {
      c.position = DeviceBuffer<glm::vec3>(n);
      c.normal = DeviceBuffer<glm::vec3>(n);
      c.depth = DeviceBuffer<float>(n);
      c.normalDistance = DeviceBuffer<float>(n);
    }
  if (volumeLayer && out.volume.size() != n) out.volume = DeviceBuffer<glm::vec4>(n);
  if (!volumeLayer) out.volume = DeviceBuffer<glm::vec4>();
  out.width = width;
  out.height = height;

  ClearViewExtractParams p;
  p.camera = FrustumMap(FrustumGrid::forCamera(camera, width, height, grid.worldBounds(), 1, 1.f));
  p.volume = GridMap(grid);
  // Each isosurface's empty-space flags, alive until the kernel has run.
  std::vector<DeviceBuffer<uint8_t>> empty(contexts.size() + foci.size());
  p.contextCount = int(contexts.size());
  p.focusCount = int(foci.size());
  for (size_t k = 0; k < contexts.size(); ++k) p.contexts[k] = fieldOf(contexts[k], empty[k]);
  for (size_t k = 0; k < foci.size(); ++k) p.foci[k] = fieldOf(foci[k], empty[contexts.size() + k]);
  p.step = 0.5f * grid.minSpacing();
  const glm::vec3 diagonal = grid.worldBounds().hi - grid.worldBounds().lo;
  p.maxNormalDistance = 0.25f * glm::length(diagonal);
  p.contextOut[0] = {out.contextPosition.data(), out.contextNormal.data(), out.contextDepth.data()};
  p.normalDistance[0] = out.normalDistance.data();
  for (size_t k = 0; k < out.deeperContexts.size(); ++k) {
    ClearViewContextLayer& c = out.deeperContexts[k];
    p.contextOut[k + 1] = {c.position.data(), c.normal.data(), c.depth.data()};
    p.normalDistance[k + 1] = c.normalDistance.data();
  }
  p.focusOut = {out.focusPosition.data(), out.focusNormal.data(), out.focusDepth.data()};
  if (volumeLayer) {
    p.volumeLayer = true;
    p.scalars = FieldView(volume.normalized);
    p.transfer = TransferLookup{transfer.data(), int(transfer.size())};
    p.volumeOut = out.volume.data();
  }
  const ClearViewExtractKernel kernel{p};
  const int64_t hits = exec::reduce("clearview: extract", int64_t(n), int64_t(0), kernel,
                                    [] VISOPT_HD(int64_t a, int64_t b) { return a + b; });
  out.contextPixels = hits % ClearViewExtractKernel::kFocusHit;
  out.focusPixels = hits / ClearViewExtractKernel::kFocusHit;
  for (ClearViewContextLayer& c : out.deeperContexts) {
    const float* depth = c.depth.data();
    c.pixels = exec::reduce(
        "clearview: count hits", int64_t(n), int64_t(0),
        [=] VISOPT_HD(int64_t i) { return int64_t(depth[i] < kClearViewNoHit ? 1 : 0); },
        [] VISOPT_HD(int64_t a, int64_t b) { return a + b; });
  }
}

namespace {

size_t focusPixelIndex(const ClearViewLayers& layers, glm::vec2 focusPixel) {
  const float fx = focusPixel.x < 0.f ? 0.5f * float(layers.width) : focusPixel.x;
  const float fy = focusPixel.y < 0.f ? 0.5f * float(layers.height) : focusPixel.y;
  const int x = std::clamp(int(std::floor(fx)), 0, layers.width - 1);
  const int y = std::clamp(int(std::floor(fy)), 0, layers.height - 1);
  return size_t(y) * size_t(layers.width) + size_t(x);
}

}  // namespace

float automaticClearViewSize(const ClearViewLayers& layers, glm::vec2 focusPixel, float fallback) {
  if (layers.width <= 0 || layers.height <= 0) return fallback;
  const size_t i = focusPixelIndex(layers, focusPixel);
  const float tc = layers.contextDepth[i], tf = layers.focusDepth[i];
  if (!(tc < kClearViewNoHit) || !(tf < kClearViewNoHit) || !(tf > tc)) return fallback;
  return std::max(2.f * (tf - tc), 0.1f * fallback);
}

bool clearViewFocusPoint(const ClearViewLayers& layers, glm::vec2 focusPixel, glm::vec3& point) {
  if (layers.width <= 0 || layers.height <= 0) return false;
  const size_t i = focusPixelIndex(layers, focusPixel);
  if (!(layers.focusDepth[i] < kClearViewNoHit)) return false;
  point = layers.focusPosition[i];
  return true;
}

void compositeClearView(const ClearViewLayers& layers, const ClearViewSettings& settings,
                        const Camera& camera, const PointLight& light, float defaultSize,
                        ClearViewStats* stats, Image& image) {
  if (settings.width != layers.width || settings.height != layers.height)
    throw Error(ErrorKind::Usage, "ClearView: the image size differs from the layers'");
  const auto start = std::chrono::steady_clock::now();
  ClearViewCompositeParams p;
  p.width = layers.width;
  p.height = layers.height;
  p.layers = layers.view();
  p.eye = camera.eye;
  p.headlight = settings.headlight;
  p.lightPosition = light.position;
  p.hasFocusPoint = clearViewFocusPoint(layers, settings.focusPixel, p.focusPoint);
  const float size = settings.size > 0.f
                         ? settings.size
                         : automaticClearViewSize(layers, settings.focusPixel, defaultSize);
  const float distance = settings.distanceScale > 0.f ? settings.distanceScale : size;
  p.invSize = 1.f / size;
  p.invDistance = 1.f / distance;
  p.weight = settings.weight;
  p.measure = static_cast<ClearViewMeasureKind>(static_cast<int>(settings.measure));
  p.contextShader = static_cast<ClearViewShaderKind>(static_cast<int>(settings.contextShader));
  p.focusShader = static_cast<ClearViewShaderKind>(static_cast<int>(settings.focusShader));
  p.contextColor = toDisplay(settings.contextColor);
  p.focusColor = toDisplay(settings.focusColor);
  p.background = toDisplay(settings.background);
  p.ambient = settings.ambient;
  p.border = settings.border;
  // Decoding display values to linear light through a table: three powf per pixel would cost
  // the compositing more than all of its blending.
  DeviceBuffer<float> decode(kClearViewDecodeEntries);
  for (int i = 0; i < kClearViewDecodeEntries; ++i)
    decode[size_t(i)] = srgbToLinear(float(i) / float(kClearViewDecodeEntries - 1));
  p.decode = decode.data();
  const size_t n = size_t(p.width) * size_t(p.height);
  if (image.width != p.width || image.height != p.height || image.pixels.size() != n)
    image = Image(p.width, p.height);
  // The CPU backend writes the image itself; a device writes to its memory, copied after.
  const bool onHost = activeBackend() == Backend::CPU;
  DeviceBuffer<glm::vec3> linear(onHost ? 0 : n);
  p.out = onHost ? image.pixels.data() : linear.data();
  exec::parallelFor("clearview: composite", int64_t(n), ClearViewCompositeKernel{p});
  if (!onHost) std::copy(linear.data(), linear.data() + n, image.pixels.begin());
  if (stats) {
    stats->compositeMs = msSince(start);
    stats->hasFocusPoint = p.hasFocusPoint;
    stats->size = size;
    stats->focusPoint = p.focusPoint;
    stats->contextPixels = layers.contextPixels;
    stats->focusPixels = layers.focusPixels;
    stats->deeperContextPixels.clear();
    for (const ClearViewContextLayer& c : layers.deeperContexts)
      stats->deeperContextPixels.push_back(c.pixels);
  }
}

}  // namespace visopt
