// Moment images (Rapp et al. 2022): generation, the per-pixel moment count, the Lagrange
// multipliers, and rendering (kernels/moment_image.h), launched on the active backend.
#include "visopt/moment_image.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "core/device_buffer.h"
#include "core/field_view.h"
#include "core/frustum_map.h"
#include "exec/parallel.h"
#include "kernels/bounded_mese_batch.h"
#include "kernels/moment_image.h"
#include "visopt/colormap.h"
#include "visopt/error.h"
#include "visopt/exec.h"
#include "visopt/frustum.h"

namespace visopt {

static_assert(kMaxMomentOrder + 1 <= kMomentCapacity);

namespace {

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

FrustumMap cameraMap(const Camera& camera, int width, int height, const GridSpec& grid) {
  // Only the rays matter here (FrustumMap::rayDirection): the depth range is unused.
  return FrustumMap(
      FrustumGrid::forCamera(camera, width, height, grid.worldBounds(), 1, grid.minSpacing()));
}

void checkStep(float stepVoxels, const char* what) {
  if (!(stepVoxels >= 0.01f && stepVoxels <= 16.f))
    throw Error(ErrorKind::Usage, std::string(what) + " must be within 0.01..16 voxels, got " +
                                      std::to_string(stepVoxels));
}

// The transfer function baked over the volume's value range, with its cumulative integrals over
// the table index (trapezoids) for pre-integration.
struct BakedTransfer {
  DeviceBuffer<glm::vec4> table, cumulative;
  MomentTransfer view(bool preintegrate) const {
    return MomentTransfer{table.data(), cumulative.data(), int(table.size()), preintegrate};
  }
};

BakedTransfer bakeTransfer(const TransferFunction& tf, double valueMin, double valueMax,
                           float minSpacing) {
  const TransferTable baked = tf.bake(valueMin, valueMax, minSpacing, 1024);
  BakedTransfer out{DeviceBuffer<glm::vec4>(baked.albedoExtinction.size()),
                    DeviceBuffer<glm::vec4>(baked.albedoExtinction.size())};
  glm::dvec4 sum(0.0);
  for (size_t i = 0; i < baked.albedoExtinction.size(); ++i) {
    const glm::vec4 e = baked.albedoExtinction[i];
    out.table[i] = e;
    if (i > 0) {
      const glm::vec4 p = baked.albedoExtinction[i - 1];
      const glm::dvec4 a(glm::dvec3(glm::vec3(p)) * double(p.w), double(p.w));
      const glm::dvec4 b(glm::dvec3(glm::vec3(e)) * double(e.w), double(e.w));
      sum += 0.5 * (a + b);
    }
    out.cumulative[i] = glm::vec4(sum);
  }
  return out;
}

Image toImage(const DeviceBuffer<glm::vec3>& pixels, int width, int height) {
  Image image(width, height);
  std::copy(pixels.data(), pixels.data() + pixels.size(), image.pixels.begin());
  return image;
}

}  // namespace

const char* toString(MomentReconstruction r) {
  return r == MomentReconstruction::BoundedMese ? "mese" : "fourier";
}

void checkMomentImageSettings(const MomentImageSettings& s) {
  if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
    throw Error(ErrorKind::Usage,
                "moment image size must be within 1..16384 pixels per side, got " +
                    std::to_string(s.width) + "x" + std::to_string(s.height));
  if (s.moments < 0 || s.moments > kMaxMomentOrder)
    throw Error(ErrorKind::Usage, "moments must be within 0.." + std::to_string(kMaxMomentOrder) +
                                      ", got " + std::to_string(s.moments));
  if (!(s.errorThreshold >= 0.f && s.errorThreshold <= 1.f))
    throw Error(ErrorKind::Usage, "moment error threshold must be within 0..1");
  if (!(s.boundsMargin > 0.f && s.boundsMargin <= 0.5f))
    throw Error(ErrorKind::Usage, "moment bounds margin must be within (0, 0.5]");
  checkStep(s.stepVoxels, "moment generation step");
  if (!(s.uncertaintyQuantile >= 0.f && s.uncertaintyQuantile < 1.f))
    throw Error(ErrorKind::Usage, "uncertainty quantile must be within [0, 1) (0: none)");
}

std::vector<uint64_t> MomentImage::offsets() const {
  std::vector<uint64_t> out(pixelCount() + 1, 0);
  for (size_t p = 0; p < pixelCount(); ++p) out[p + 1] = out[p] + counts[p];
  return out;
}

namespace {

// §3.5's per-pixel counts and the stored form of `pixels` pixels, from their moments rescaled by
// Eq. 5 (`dense`, order + 1 per pixel) and their bounds.
MomentPixels countAndPack(const DeviceBuffer<float>& dense, const DeviceBuffer<float>& lower,
                          const DeviceBuffer<float>& upper, size_t pixels,
                          const MomentImageSettings& settings, double* countMs) {
  const int stride = settings.moments + 1;
  DeviceBuffer<uint8_t> counts(std::max<size_t>(pixels, 1));
  const auto t1 = std::chrono::steady_clock::now();
  exec::parallelFor("moments: count", int64_t(pixels),
                    MomentCount{dense.data(), lower.data(), upper.data(), settings.moments,
                                double(settings.errorThreshold), counts.data()});
  if (countMs) *countMs += msSince(t1);
  MomentPixels out;
  out.counts.assign(counts.data(), counts.data() + pixels);
  out.lower.assign(lower.data(), lower.data() + pixels);
  out.upper.assign(upper.data(), upper.data() + pixels);
  size_t stored = 0;
  for (size_t p = 0; p < pixels; ++p) {
    stored += out.counts[p];
    if (out.counts[p] == 0) out.lower[p] = out.upper[p] = 0.f;
  }
  out.moments.reserve(stored);
  for (size_t p = 0; p < pixels; ++p)
    out.moments.insert(out.moments.end(), dense.data() + p * stride,
                       dense.data() + p * stride + out.counts[p]);
  return out;
}

void fillStats(const MomentImage& image, int64_t samplesTaken, double countMs,
               MomentGenerationStats* stats) {
  if (!stats) return;
  int64_t hit = 0;
  for (uint8_t c : image.counts) hit += c > 0;
  stats->countMs = countMs;
  stats->samples = samplesTaken;
  stats->meanMoments = hit > 0 ? double(image.moments.size()) / double(hit) : 0.0;
}

}  // namespace

MomentImage generateMomentImage(const Volume& volume, const Camera& camera,
                                const MomentImageSettings& settings, MomentGenerationStats* stats) {
  checkMomentImageSettings(settings);
  const GridSpec& grid = volume.grid();
  checkCamera(camera, grid.worldBounds(), "moment image camera");
  const size_t pixels = size_t(settings.width) * size_t(settings.height);
  const int stride = settings.moments + 1;
  DeviceBuffer<float> dense(pixels * size_t(stride)), lower(pixels), upper(pixels);
  DeviceBuffer<int> samples(pixels);

  const auto t0 = std::chrono::steady_clock::now();
  MomentGeneration gen;
  gen.camera = cameraMap(camera, settings.width, settings.height, grid);
  gen.volume = GridMap(grid);
  gen.density = FieldView(volume.normalized);
  gen.order = settings.moments;
  gen.step = settings.stepVoxels * grid.minSpacing();
  gen.margin = settings.boundsMargin;
  gen.moments = dense.data();
  gen.lower = lower.data();
  gen.upper = upper.data();
  gen.samples = samples.data();
  exec::parallelFor("moments: generate", int64_t(pixels), gen);
  const double marchMs = msSince(t0);

  int64_t taken = 0;
  for (size_t p = 0; p < pixels; ++p) taken += samples[p];
  double countMs = 0.0;
  MomentImage out = momentImageOf(countAndPack(dense, lower, upper, pixels, settings, &countMs),
                                  grid, camera, settings, volume.valueMin, volume.valueMax);
  fillStats(out, taken, countMs, stats);
  if (settings.uncertaintyQuantile > 0.f) {
    const auto t2 = std::chrono::steady_clock::now();
    const std::vector<uint64_t> offsets = out.offsets();
    DeviceBuffer<uint64_t> off(offsets.size());
    std::copy(offsets.begin(), offsets.end(), off.data());
    DeviceBuffer<float> kept(std::max<size_t>(out.moments.size(), 1)), error(pixels);
    std::copy(out.moments.begin(), out.moments.end(), kept.data());
    exec::parallelFor("moments: uncertainty", int64_t(pixels),
                      MomentUncertainty{gen.camera, gen.volume, gen.density, gen.step,
                                        settings.uncertaintyQuantile, off.data(), kept.data(),
                                        lower.data(), upper.data(), error.data()});
    out.uncertaintyQuantile = settings.uncertaintyQuantile;
    out.uncertainty.assign(error.data(), error.data() + pixels);
    if (stats) stats->uncertaintyMs = msSince(t2);
  }
  if (stats) stats->marchMs = marchMs;
  return out;
}

MomentPartials emptyMomentPartials(const MomentImageSettings& settings) {
  checkMomentImageSettings(settings);
  MomentPartials p;
  p.width = settings.width;
  p.height = settings.height;
  p.order = settings.moments;
  const size_t pixels = size_t(p.width) * size_t(p.height);
  p.moments.assign(pixels * size_t(p.order + 1), 0.0);
  p.lower.assign(pixels, 1e30f);
  p.upper.assign(pixels, -1e30f);
  return p;
}

int momentSlabHalo(const MomentImageSettings& settings) {
  // A slab's piece ends one step past its last sample: at most stepVoxels slices along z
  // (the step is stepVoxels times the smallest spacing), and the trilinear sample there reads
  // the slice above.
  return int(std::ceil(settings.stepVoxels)) + 1;
}

void addMomentSlab(MomentPartials& partials, const Field3D& slab, int slabFirst, int ownedBegin,
                   int ownedEnd, const GridSpec& grid, const Camera& camera,
                   const MomentImageSettings& settings, double* marchMs) {
  checkMomentImageSettings(settings);
  checkCamera(camera, grid.worldBounds(), "moment image camera");
  if (partials.width != settings.width || partials.height != settings.height ||
      partials.order != settings.moments)
    throw Error(ErrorKind::Usage, "moment partials were made for other settings");
  const glm::ivec3 dims = grid.dims, sd = slab.grid().dims;
  if (!(0 <= ownedBegin && ownedBegin < ownedEnd && ownedEnd <= dims.z))
    throw Error(ErrorKind::Usage, "a moment slab must own slices within 0.." +
                                      std::to_string(dims.z) + ", got " +
                                      std::to_string(ownedBegin) + ".." + std::to_string(ownedEnd));
  const int halo = momentSlabHalo(settings);
  const int need0 = std::max(0, ownedBegin - halo), need1 = std::min(dims.z, ownedEnd + halo);
  if (sd.x != dims.x || sd.y != dims.y || slabFirst > need0 || slabFirst + sd.z < need1)
    throw Error(ErrorKind::Usage, "a moment slab owning slices " + std::to_string(ownedBegin) +
                                      ".." + std::to_string(ownedEnd) + " must hold slices " +
                                      std::to_string(need0) + ".." + std::to_string(need1));
  const auto t0 = std::chrono::steady_clock::now();
  const size_t pixels = size_t(settings.width) * size_t(settings.height);
  const int stride = settings.moments + 1;
  // The CPU backend adds to the partials in place; a device adds to copies in its memory (on a
  // 512^2 image of 100 moments each copy is 210 MB, twice per slab).
  const bool onHost = activeBackend() == Backend::CPU;
  DeviceBuffer<double> moments(onHost ? 0 : pixels * size_t(stride));
  DeviceBuffer<float> lower(onHost ? 0 : pixels), upper(onHost ? 0 : pixels);
  if (!onHost) {
    std::copy(partials.moments.begin(), partials.moments.end(), moments.data());
    std::copy(partials.lower.begin(), partials.lower.end(), lower.data());
    std::copy(partials.upper.begin(), partials.upper.end(), upper.data());
  }
  MomentSlabGeneration gen;
  gen.camera = cameraMap(camera, settings.width, settings.height, grid);
  gen.volume = GridMap(grid);
  gen.density = SlabDensity{FieldView(slab), dims, slabFirst};
  gen.ownedBegin = ownedBegin == 0 ? -1e30f : float(ownedBegin);
  gen.ownedEnd = ownedEnd == dims.z ? 1e30f : float(ownedEnd);
  gen.order = settings.moments;
  gen.step = settings.stepVoxels * grid.minSpacing();
  gen.moments = onHost ? partials.moments.data() : moments.data();
  gen.lower = onHost ? partials.lower.data() : lower.data();
  gen.upper = onHost ? partials.upper.data() : upper.data();
  exec::parallelFor("moments: generate slab", int64_t(pixels), gen);
  if (!onHost) {
    std::copy(moments.data(), moments.data() + moments.size(), partials.moments.begin());
    std::copy(lower.data(), lower.data() + pixels, partials.lower.begin());
    std::copy(upper.data(), upper.data() + pixels, partials.upper.begin());
  }
  if (marchMs) *marchMs += msSince(t0);
}

void mergeMomentPartials(MomentPartials& into, const MomentPartials& other) {
  if (into.width != other.width || into.height != other.height || into.order != other.order)
    throw Error(ErrorKind::Usage, "moment partials of different images cannot be merged");
  for (size_t i = 0; i < into.moments.size(); ++i) into.moments[i] += other.moments[i];
  for (size_t p = 0; p < into.lower.size(); ++p) {
    into.lower[p] = std::min(into.lower[p], other.lower[p]);
    into.upper[p] = std::max(into.upper[p], other.upper[p]);
  }
}

MomentPixels finishMomentPixels(std::span<const double> moments, std::span<const float> lower,
                                std::span<const float> upper, const MomentImageSettings& settings,
                                double* countMs) {
  checkMomentImageSettings(settings);
  const size_t pixels = lower.size();
  const int stride = settings.moments + 1;
  if (upper.size() != pixels || moments.size() != pixels * size_t(stride))
    throw Error(ErrorKind::Usage, "moment partials of " + std::to_string(pixels) +
                                      " pixels need as many bounds and order + 1 moments each");
  DeviceBuffer<float> dense(std::max<size_t>(pixels * size_t(stride), 1)),
      lo(std::max<size_t>(pixels, 1)), hi(std::max<size_t>(pixels, 1));
  for (size_t p = 0; p < pixels; ++p) {
    float* out = dense.data() + p * size_t(stride);
    if (!(lower[p] <= upper[p])) {  // no slab had a sample: the ray misses the volume
      std::fill(out, out + stride, 0.f);
      lo[p] = 1.f;
      hi[p] = 0.f;
      continue;
    }
    MomentGeneration::rescaleMoments(moments.data() + p * size_t(stride), settings.moments,
                                     lower[p], upper[p], settings.boundsMargin, out, lo[p], hi[p]);
  }
  return countAndPack(dense, lo, hi, pixels, settings, countMs);
}

MomentImage momentImageOf(MomentPixels pixels, const GridSpec& grid, const Camera& camera,
                          const MomentImageSettings& settings, double valueMin, double valueMax) {
  const size_t n = size_t(settings.width) * size_t(settings.height);
  if (pixels.counts.size() != n || pixels.lower.size() != n || pixels.upper.size() != n)
    throw Error(ErrorKind::Usage, "a moment image of " + std::to_string(settings.width) + "x" +
                                      std::to_string(settings.height) + " needs " +
                                      std::to_string(n) + " finished pixels");
  MomentImage out;
  out.width = settings.width;
  out.height = settings.height;
  out.order = settings.moments;
  out.camera = camera;
  out.grid = grid;
  out.valueMin = valueMin;
  out.valueMax = valueMax;
  out.boundsMargin = settings.boundsMargin;
  out.errorThreshold = settings.errorThreshold;
  out.stepVoxels = settings.stepVoxels;
  out.counts = std::move(pixels.counts);
  out.lower = std::move(pixels.lower);
  out.upper = std::move(pixels.upper);
  out.moments = std::move(pixels.moments);
  return out;
}

MomentImage finishMomentImage(const MomentPartials& total, const GridSpec& grid,
                              const Camera& camera, const MomentImageSettings& settings,
                              double valueMin, double valueMax, MomentGenerationStats* stats) {
  checkMomentImageSettings(settings);
  if (settings.uncertaintyQuantile > 0.f)
    throw Error(ErrorKind::Usage,
                "the uncertainty (§4.1) needs each whole ray: distributed generation does not "
                "compute it");
  if (total.width != settings.width || total.height != settings.height ||
      total.order != settings.moments)
    throw Error(ErrorKind::Usage, "moment partials were made for other settings");
  double countMs = 0.0;
  MomentImage out =
      momentImageOf(finishMomentPixels(total.moments, total.lower, total.upper, settings, &countMs),
                    grid, camera, settings, valueMin, valueMax);
  if (stats) {
    const FrustumMap map = cameraMap(camera, settings.width, settings.height, grid);
    const GridMap volume(grid);
    const float step = settings.stepVoxels * grid.minSpacing();
    int64_t taken = 0;
    for (size_t p = 0; p < out.pixelCount(); ++p)
      if (out.counts[p] > 0) taken += momentSampleCount(momentRay(map, volume, int64_t(p)), step);
    fillStats(out, taken, countMs, stats);
  }
  return out;
}

namespace {

// The Lagrange multipliers of every pixel's stored moments (§3.3: computed once on loading),
// real and imaginary parts at the pixel's offsets. A pixel whose higher moments do not form a
// valid sequence (quantization could do that; float storage rarely) keeps the valid prefix: its
// unused multipliers are zero. One call serves kMeseBatch consecutive pixels: on the CPU side
// by side (kernels/bounded_mese_batch.h), on a GPU thread one after the other.
struct LagrangeOfPixelBatches {
  int64_t pixels = 0;
  const uint64_t* offsets = nullptr;
  const float* moments = nullptr;
  float* re = nullptr;
  float* im = nullptr;
  bool perPixel = false;  // pixelMultipliers one pixel at a time (the reference)

  VISOPT_HD void operator()(int64_t batch) const {
    const int64_t first = batch * kMeseBatch;
    const int lanes = int(pixels - first < kMeseBatch ? pixels - first : kMeseBatch);
#if !defined(VISOPT_ON_DEVICE)
    if (!perPixel) {
      batched(first, lanes);
      return;
    }
#endif
    for (int b = 0; b < lanes; ++b) {
      const uint64_t begin = offsets[first + b];
      const int count = int(offsets[first + b + 1] - begin);
      if (count > 0) pixelMultipliers(moments + begin, count, re + begin, im + begin);
    }
  }

#if !defined(VISOPT_ON_DEVICE)
  void batched(int64_t first, int lanes) const {
    MeseBatch job;
    for (double& c : job.c) c = 0.0;
    for (int b = 0; b < kMeseBatch; ++b) {
      job.m[b] = -1;
      if (b >= lanes) continue;
      const uint64_t begin = offsets[first + b];
      const int count = int(offsets[first + b + 1] - begin);
      job.m[b] = count - 1;
      for (int j = 0; j < count; ++j) job.c[j * kMeseBatch + b] = double(moments[begin + j]);
    }
    boundedMeseBatch(job);
    for (int b = 0; b < lanes; ++b) {
      const uint64_t begin = offsets[first + b];
      const int count = job.m[b] + 1, order = job.order[b];
      for (int j = 0; j < count; ++j) {
        re[begin + j] = j <= order ? float(job.lambdaRe[j * kMeseBatch + b]) : 0.f;
        im[begin + j] = j <= order ? float(job.lambdaIm[j * kMeseBatch + b]) : 0.f;
      }
      if (count > 0 && order < 0) re[begin] = constantMultiplier(job.c[b]);
    }
  }
#endif
};

}  // namespace

Image renderMomentImage(const MomentImage& image, const TransferFunction& tf,
                        const MomentRenderSettings& settings) {
  checkStep(settings.stepVoxels, "moment render step");
  const size_t pixels = image.pixelCount();
  const std::vector<uint64_t> offsets = image.offsets();
  DeviceBuffer<uint64_t> off(offsets.size());
  std::copy(offsets.begin(), offsets.end(), off.data());
  const size_t stored = image.moments.size();
  DeviceBuffer<float> values(std::max<size_t>(stored, 1)), imag;
  DeviceBuffer<float> lower(pixels), upper(pixels);
  std::copy(image.lower.begin(), image.lower.end(), lower.data());
  std::copy(image.upper.begin(), image.upper.end(), upper.data());
  if (settings.reconstruction == MomentReconstruction::BoundedMese) {
    DeviceBuffer<float> moments(std::max<size_t>(stored, 1));
    std::copy(image.moments.begin(), image.moments.end(), moments.data());
    imag = DeviceBuffer<float>(std::max<size_t>(stored, 1));
    LagrangeOfPixelBatches k{int64_t(pixels), off.data(),  moments.data(),
                             values.data(),   imag.data(), settings.perSampleReference};
    exec::parallelFor("moments: lagrange multipliers",
                      (int64_t(pixels) + kMeseBatch - 1) / kMeseBatch, k);
  } else {
    std::copy(image.moments.begin(), image.moments.end(), values.data());
  }
  const BakedTransfer baked =
      bakeTransfer(tf, image.valueMin, image.valueMax, image.grid.minSpacing());
  DeviceBuffer<glm::vec3> out(pixels);
  MomentRender k;
  k.camera = cameraMap(image.camera, image.width, image.height, image.grid);
  k.volume = GridMap(image.grid);
  k.tf = baked.view(settings.preintegrate);
  k.step = settings.stepVoxels * image.grid.minSpacing();
  k.offsets = off.data();
  k.values = values.data();
  k.imag = settings.reconstruction == MomentReconstruction::BoundedMese ? imag.data() : nullptr;
  k.lower = lower.data();
  k.upper = upper.data();
  k.out = out.data();
  k.perSample = settings.perSampleReference;
  exec::parallelFor("moments: render", int64_t(pixels), k);
  return toImage(out, image.width, image.height);
}

Image renderVolumeEmissionAbsorption(const Volume& volume, const Camera& camera, int width,
                                     int height, const TransferFunction& tf,
                                     const MomentRenderSettings& settings) {
  checkStep(settings.stepVoxels, "render step");
  const GridSpec& grid = volume.grid();
  checkCamera(camera, grid.worldBounds(), "camera");
  const BakedTransfer baked = bakeTransfer(tf, volume.valueMin, volume.valueMax, grid.minSpacing());
  DeviceBuffer<glm::vec3> out(size_t(width) * size_t(height));
  VolumeEmissionAbsorption k;
  k.camera = cameraMap(camera, width, height, grid);
  k.volume = GridMap(grid);
  k.density = FieldView(volume.normalized);
  k.tf = baked.view(settings.preintegrate);
  k.step = settings.stepVoxels * grid.minSpacing();
  k.out = out.data();
  exec::parallelFor("moments: direct render", int64_t(out.size()), k);
  return toImage(out, width, height);
}

float uncertaintyHeatMapTop(const MomentImage& image, float maxError) {
  if (maxError > 0.f) return maxError;
  float top = 0.f;
  for (float e : image.uncertainty) top = std::max(top, e);
  return top;
}

Image renderMomentUncertainty(const MomentImage& image, float maxError) {
  if (image.uncertainty.size() != image.pixelCount())
    throw Error(ErrorKind::Usage,
                "the moment image holds no uncertainty (generate it with an uncertainty quantile)");
  const float top = uncertaintyHeatMapTop(image, maxError);
  Image out(image.width, image.height);
  for (size_t p = 0; p < image.pixelCount(); ++p)
    out.pixels[p] =
        image.counts[p] == 0
            ? glm::vec3(0.f)
            : evaluateColormap(Colormap::Magma,
                               top > 0.f ? std::min(image.uncertainty[p] / top, 1.f) : 0.f);
  return out;
}

namespace {

int64_t pixelOf(const MomentImage& image, int x, int y) {
  if (x < 0 || y < 0 || x >= image.width || y >= image.height)
    throw Error(ErrorKind::Usage, "pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                      ") is outside the moment image");
  return int64_t(y) * image.width + x;
}

}  // namespace

std::vector<float> reconstructRay(const MomentImage& image, int x, int y, int samples,
                                  MomentReconstruction r) {
  const int64_t p = pixelOf(image, x, y);
  // The pixel's first moment: the counts before it (one pixel's query needs no offset table).
  const uint64_t begin =
      std::accumulate(image.counts.begin(), image.counts.begin() + p, uint64_t(0));
  const int count = int(image.counts[size_t(p)]);
  std::vector<float> out(size_t(std::max(samples, 0)), 0.f);
  if (count == 0 || samples < 2) return out;
  std::vector<float> re(count), im(count);
  const float* c = image.moments.data() + begin;
  int order = count - 1;
  if (r == MomentReconstruction::BoundedMese)
    order = pixelMultipliers(c, count, re.data(), im.data());
  else
    std::copy(c, c + count, re.begin());
  MomentDensity d{re.data(), r == MomentReconstruction::BoundedMese ? im.data() : nullptr, order,
                  image.lower[p], image.upper[p]};
  for (int k = 0; k < samples; ++k)
    out[k] = d.at(-float(kMomentPi) + float(kMomentPi) * float(k) / float(samples - 1));
  return out;
}

std::vector<float> sampleRay(const Volume& volume, const MomentImage& image, int x, int y,
                             int samples) {
  const int64_t p = pixelOf(image, x, y);
  const MomentRay r = momentRay(cameraMap(image.camera, image.width, image.height, image.grid),
                                GridMap(image.grid), p);
  std::vector<float> out(size_t(std::max(samples, 0)), 0.f);
  if (!r.hits() || samples < 2) return out;
  const FieldView density(volume.normalized);
  for (int k = 0; k < samples; ++k) {
    const float t = r.t0 + (r.t1 - r.t0) * float(k) / float(samples - 1);
    out[k] = std::clamp(density.sample(r.o + t * r.d), 0.f, 1.f);
  }
  return out;
}

}  // namespace visopt
