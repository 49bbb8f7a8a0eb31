#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "core/field_view.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "kernels/ray_march.h"
#include "kernels/ray_skip.h"
#include "kernels/surface_render.h"
#include "kernels/transmittance_scan.h"
#include "kernels/volume_extinction.h"
#include "render/abandonable_bands.h"
#include "visopt/error.h"

namespace visopt {

namespace {

TransferLookup lookupOf(const RenderScene& scene) {
  return TransferLookup{scene.transfer->data(), int(scene.transfer->size())};
}

VolumeExtinction extinctionOf(const RenderScene& scene) {
  VolumeExtinction e;
  e.scalars = FieldView(scene.volume->normalized);
  if (scene.extinctionChange) e.change = FieldView(*scene.extinctionChange);
  e.transfer = lookupOf(scene);
  return e;
}

// Bilinear upscaling of a preview image to the requested size.
Image upscale(const Image& small, int width, int height) {
  Image out(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float sx = std::clamp((float(x) + 0.5f) * float(small.width) / float(width) - 0.5f, 0.f,
                            float(small.width - 1));
      float sy = std::clamp((float(y) + 0.5f) * float(small.height) / float(height) - 0.5f, 0.f,
                            float(small.height - 1));
      int x0 = int(sx), y0 = int(sy);
      int x1 = std::min(x0 + 1, small.width - 1), y1 = std::min(y0 + 1, small.height - 1);
      float fx = sx - float(x0), fy = sy - float(y0);
      glm::vec3 a = glm::mix(small.at(x0, y0), small.at(x1, y0), fx);
      glm::vec3 b = glm::mix(small.at(x0, y1), small.at(x1, y1), fx);
      out.at(x, y) = glm::mix(a, b, fy);
    }
  return out;
}

// The empty-block grid of kernels/ray_skip.h for marching with segments of at most `step`, or
// an invalid grid when nothing can be skipped: the transfer function has no transparent range
// and mu is not an optimised field.
struct SkipGridStorage {
  DeviceBuffer<glm::vec2> range, changeRange;
  DeviceBuffer<int> nonEmptyBefore;
  DeviceBuffer<uint8_t> empty;
  RaySkipGrid grid;
};

void buildSkipGrid(const RenderScene& scene, float step, SkipGridStorage& out) {
  // Extinction at or below this leaves every segment's optical depth under the marcher's
  // threshold (with a margin for rounding in the interpolations and the segment length).
  const float negligible = kRayMinOpticalDepth / (step * 1.001f);
  RaySkipFlags flags;
  const DeviceBuffer<glm::vec4>& table = *scene.transfer;
  out.nonEmptyBefore = DeviceBuffer<int>(table.size() + 1);
  int count = 0;
  for (size_t i = 0; i < table.size(); ++i) {
    out.nonEmptyBefore[i] = count;
    if (!(table[i].w < negligible)) ++count;
  }
  out.nonEmptyBefore[table.size()] = count;
  if (count == int(table.size())) return;  // nothing transparent
  flags.nonEmptyBefore = out.nonEmptyBefore.data();
  flags.tableSize = int(table.size());
  // The change is sampled at the volume's index coordinates: only a field on the volume's grid.
  if (scene.extinctionChange && scene.extinctionChange->grid().dims != scene.volume->grid().dims)
    return;
  const glm::ivec3 blocks = raySkipBlocks(scene.volume->grid().dims);
  const int64_t n = int64_t(blocks.x) * blocks.y * blocks.z;
  out.empty = DeviceBuffer<uint8_t>(size_t(n));
  // The caller's ranges when it kept them for these fields, else the frame's own.
  auto ranges = [n](const DeviceBuffer<glm::vec2>* kept, const Field3D& field,
                    DeviceBuffer<glm::vec2>& own) -> const glm::vec2* {
    if (kept && kept->size() == size_t(n)) return kept->data();
    own = computeBlockRange(field);
    return own.data();
  };
  flags.range = ranges(scene.volumeBlockRange, scene.volume->normalized, out.range);
  if (scene.extinctionChange)
    flags.changeRange = ranges(scene.changeBlockRange, *scene.extinctionChange, out.changeRange);
  flags.blocks = blocks;
  flags.empty = out.empty.data();
  exec::parallelFor("render skip flags", n, flags);
  out.grid.empty = out.empty.data();
  out.grid.dims = blocks;
}

}  // namespace

DeviceBuffer<glm::vec2> computeBlockRange(const Field3D& field) {
  const FieldView view(field);
  const glm::ivec3 blocks = raySkipBlocks(view.dims);
  const int64_t n = int64_t(blocks.x) * blocks.y * blocks.z;
  DeviceBuffer<glm::vec2> range(static_cast<size_t>(n));
  exec::parallelFor("render skip ranges", n, RaySkipRange{view, blocks, range.data()});
  return range;
}

void computeExtinctionChange(const Volume& volume, const DeviceBuffer<glm::vec4>& transfer,
                             const Field3D& mu, Field3D& out) {
  if (out.grid().dims != volume.grid().dims)
    throw Error(ErrorKind::Failure, "the extinction change is not on the volume's grid");
  const FieldView scalars(volume.normalized), from(mu), to(out);
  const TransferLookup table{transfer.data(), int(transfer.size())};
  const GridMap voxels(volume.grid()), muGrid(mu.grid());
  const bool same = mu.grid().dims == volume.grid().dims;
  exec::parallelFor("render: extinction change", int64_t(out.size()), [=] VISOPT_HD(int64_t v) {
    float m;
    if (same) {
      m = from.load(size_t(v));
    } else {
      const auto [i, j, k] = voxels.ijk(v);
      m = from.sample(muGrid.toIndex(voxels.toWorld(glm::vec3(float(i), float(j), float(k)))));
    }
    to.store(size_t(v), m - table.at(scalars.load(size_t(v))).w);
  });
}

bool computeLightTransmittance(const RenderScene& scene, const FrustumGrid& lightFrustum,
                               Field3D& out, const std::function<bool()>& abandon,
                               RenderMethod method, float cutThreshold) {
  if (out.grid().dims != lightFrustum.dims)
    throw Error(ErrorKind::Failure, "light transmittance field does not match its frustum");
  TransmittanceScan<VolumeExtinction> scan;
  scan.frustum = FrustumMap(lightFrustum);
  scan.volume = GridMap(scene.volume->grid());
  scan.out = FieldView(out);
  scan.extinction = extinctionOf(scene);
  scan.midpoint = true;
  // The maximum importance projection's light sees the volume only (kernels/ray_march.h).
  if (method != RenderMethod::MaxImportanceProjection)
    for (size_t i = 0; i < scene.surfaces.size() && i < size_t(kMaxContextSurfaces); ++i)
      scan.surfaces.phi[scan.surfaces.count++] = FieldView(*scene.surfaces[i]);
  // The baselines' surfaces as drawn: cut or faded by ghat (kernels/transmittance_scan.h).
  if ((method == RenderMethod::CutAway || method == RenderMethod::TransparencyModulation) &&
      !scan.surfaces.empty()) {
    if (!scene.importanceBehind)
      throw Error(ErrorKind::Usage,
                  std::string("the ") + toString(method) + " baseline's light needs ghat (Eq. 19)");
    scan.method = method == RenderMethod::CutAway ? RayMethod::CutAway : RayMethod::Transparency;
    scan.importanceBehind = FieldView(*scene.importanceBehind);
    scan.cutThreshold = cutThreshold;
  }
  const int64_t rays = int64_t(lightFrustum.dims.x) * lightFrustum.dims.y;
  if (!abandon) {
    exec::parallelFor("light transmittance", rays, scan);
    return true;
  }
  // 16 bands of rays, so that a newer camera need not wait for the whole grid.
  return launchInBands(rays, 16, 1, abandon, [&](int64_t first, int64_t count) {
    exec::parallelFor("light transmittance", count,
                      [=] VISOPT_HD(int64_t ray) { scan(first + ray); });
  });
}

Image renderImage(const RenderScene& scene, const RenderSettings& settings, RenderStats* stats,
                  const std::function<bool()>& abandon) {
  if (!scene.volume || !scene.transfer) throw Error(ErrorKind::Usage, "nothing to render");
  // The settings were checked by the caller (Engine::render) before it allocated anything.
  const auto start = std::chrono::steady_clock::now();
  const bool preview = settings.preview && settings.previewFactor > 1;
  const int w = preview ? std::max(1, settings.width / settings.previewFactor) : settings.width;
  const int h = preview ? std::max(1, settings.height / settings.previewFactor) : settings.height;

  const GridSpec& grid = scene.volume->grid();
  RayMarchParams p;
  p.camera = FrustumMap(FrustumGrid::forCamera(scene.camera, w, h, grid.worldBounds(), 1, 1.f));
  p.volume = GridMap(grid);
  p.scalars = FieldView(scene.volume->normalized);
  if (scene.extinctionChange) p.extinctionChange = FieldView(*scene.extinctionChange);
  p.transfer = lookupOf(scene);
  if (scene.lightTransmittance && scene.lightFrustum) {
    p.light = FrustumMap(*scene.lightFrustum);
    p.lightTransmittance = FieldView(*scene.lightTransmittance);
  }
  p.lightPosition = scene.light.position;
  p.lightRadiance = scene.light.intensity * scene.light.color;
  p.step = settings.stepFactor * grid.minSpacing() * (preview ? 2.f : 1.f);
  p.jitter = settings.jitter;
  p.seed = settings.seed;
  p.hg = std::clamp(settings.hgAnisotropy, -0.99f, 0.99f);
  p.kd = settings.diffuse;
  p.ks = settings.specular;
  p.shininess = settings.shininess;
  p.surfaceGradient = std::max(settings.surfaceGradient, 1e-6f);
  p.ambient = settings.ambient;
  if (scene.volumeOcclusion && settings.ambientOcclusion && settings.ambient > 0.f) {
    if (scene.volumeOcclusion->grid().dims != grid.dims)
      throw Error(ErrorKind::Failure, "the volume occlusion field is not on the volume's grid");
    p.volumeOcclusion = FieldView(*scene.volumeOcclusion);
  }
  p.background = settings.background;
  p.earlyStop = settings.earlyStop;
  // Context surfaces and the baselines' inputs.
  for (size_t i = 0; i < scene.surfaces.size() && i < size_t(kMaxContextSurfaces); ++i) {
    const int k = p.surf.surfaces.count++;
    p.surf.surfaces.phi[k] = FieldView(*scene.surfaces[i]);
    if (i < scene.surfaceBases.size()) p.surf.bases[k] = FieldView(*scene.surfaceBases[i]);
    p.surf.colors[k] = i < scene.surfaceColors.size() ? scene.surfaceColors[i] : glm::vec3(0.8f);
  }
  p.surf.deviationView = settings.deviationView;
  p.surf.deviationScale = 1.f / (grid.minSpacing() * std::max(settings.deviationMaxVoxels, 1e-3f));
  p.surf.deviationColormap = settings.deviationColormap;
  p.surf.ks = settings.surfaceSpecular;
  p.surf.shininess = settings.surfaceShininess;
  p.surf.ambientOcclusion = settings.ambientOcclusion;
  p.surf.aoRadius = settings.ambientOcclusionRadius * grid.minSpacing();
  p.surf.minStep = 0.25f * grid.minSpacing();
  p.surf.method = static_cast<RayMethod>(static_cast<int>(settings.method));
  // Maximum importance projection reads g; cut-away and transparency modulation read ghat
  // (Eq. 19) where there are surfaces to cut or fade (Engine::render computes it).
  if (settings.method == RenderMethod::MaxImportanceProjection && !scene.importance)
    throw Error(ErrorKind::Usage, "the maximum importance projection needs an importance");
  if ((settings.method == RenderMethod::CutAway ||
       settings.method == RenderMethod::TransparencyModulation) &&
      !p.surf.surfaces.empty() && !scene.importanceBehind)
    throw Error(ErrorKind::Usage, std::string("the ") + toString(settings.method) +
                                      " baseline needs ghat (Eq. 19) for its surfaces");
  if (scene.importanceBehind) p.surf.importanceBehind = FieldView(*scene.importanceBehind);
  if (scene.importance) p.surf.importance = FieldView(*scene.importance);
  p.surf.cutThreshold = settings.cutAwayThreshold;
  // Overlays; NaN or <= 0 leaves the importance overlay off.
  p.surf.importanceOverlay =
      settings.importanceOverlay > 0.f ? std::min(settings.importanceOverlay, 1.f) : 0.f;
  if (settings.worldMaskOverlay) p.surf.worldMask = scene.worldMask;

  SkipGridStorage skip;
  buildSkipGrid(scene, p.step, skip);
  p.skip = skip.grid;

  DeviceBuffer<glm::vec3> pixels(size_t(w) * size_t(h));
  p.pixels = pixels.data();
  const RayMarchKernel kernel(p);
  const auto sum = [] VISOPT_HD(int64_t a, int64_t b) { return a + b; };
  const int64_t items = rayMarchItems(w, h);
  int64_t samples = 0;
  if (!abandon) {
    samples = exec::reduce("render", items, int64_t(0), kernel, sum);
  } else {
    // 32 bands of whole ray tiles, so that a newer camera need not wait for the whole frame.
    const bool done = launchInBands(
        items, 32, int64_t(kRayTile) * kRayTile, abandon, [&](int64_t first, int64_t count) {
          samples += exec::reduce(
              "render", count, int64_t(0),
              [=] VISOPT_HD(int64_t item) { return kernel(first + item); }, sum);
        });
    if (!done) return Image();
  }

  Image image(w, h);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = pixels[i] * settings.exposure;
  if (preview) image = upscale(image, settings.width, settings.height);
  if (stats) {
    stats->milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    stats->samples = samples;
    stats->width = w;
    stats->height = h;
  }
  return image;
}

}  // namespace visopt
