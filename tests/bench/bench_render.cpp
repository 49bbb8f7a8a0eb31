// Render throughput: visopt's single-scattering ray marcher (with shadows from the cached light
// transmittance T_L) against VTK's CPU ray caster, vtkFixedPointVolumeRayCastMapper (shading on),
// on the same volume, transfer function, camera and image size, sampling once per voxel spacing.
//
// Benchmarks (names as Google Benchmark prints them):
//   visopt/size:N/image:M/tf:T/fp32|fp16  Engine::render(), after a warm-up render that builds
//                                         T_L
//   vtk_fixed_point/size:N/image:M/tf:T   vtkRenderWindow::Render(), after a warm-up render that
//                                         builds VTK's gradients and shading tables
// with T one of
//   scene  the built-in scene's own transfer function (zero opacity over much of the value
//          range, which VTK's min-max space leaping skips and visopt marches through);
//   dense  the same with every opacity raised to at least kDenseOpacityFloor, so there is no
//          empty space to skip and (almost) every nominal sample is taken by both renderers.
// Counters (per frame, averaged over the iterations):
//   Msps_core        nominal samples / wall second / thread, in millions
//   Msps_core_cpu    nominal samples / CPU second of the whole process (all threads), in
//                    millions: per core-second actually used, so robust against other load on a
//                    shared machine (where the wall-clock figure understates both renderers)
//   cpu_util         CPU seconds / (wall seconds * threads): the share of the cores obtained
//   Msps_core_taken, Msps_core_taken_cpu
//                    visopt only: samples actually taken (RenderStats::samples), per wall / CPU
//                    second as above
//   ms_frame         wall time of one frame (the time the benchmark reports, too)
//   mapper_ms        VTK only: the mapper's own ray-casting time for the frame
//   Msps_core_mapper VTK only: nominal samples / mapper_ms / thread
//   light_ms         visopt only: the T_L computation, measured once in the warm-up render
//   threads          threads used (oneTBB's default concurrency / the VTK mapper's threads)
//   nominal_Msamples the nominal sample count of one frame, in millions
//
// The nominal sample count is the same for both renderers: for every pixel, the length of its
// camera ray (through the pixel centre) inside the box spanned by the voxel centres, divided by
// the sample distance and rounded up, summed over pixels. Neither renderer's empty-space
// skipping or early ray termination changes it, so the ratio of the two Msps_core figures is the
// ratio of frame times.
//
// The VTK benchmarks need an X display (the offscreen window is still an X/GLX window on Debian's
// VTK): run under `xvfb-run -a`. Without DISPLAY they are skipped with a message.
// Environment: VISOPT_BENCH_SCENE (default marschner-lobb) picks the built-in scene;
// VISOPT_BENCH_DUMP=DIR writes each case's warm-up image there as PNG, to compare the views.
#include <benchmark/benchmark.h>

#include <tbb/info.h>

#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkFixedPointVolumeRayCastMapper.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMultiThreader.h>
#include <vtkNew.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>

#include <time.h>

#include "visopt/engine.h"
#include "visopt/exec.h"
#include "visopt/image.h"
#include "visopt/scenes.h"

namespace {

using Clock = std::chrono::steady_clock;

const int kVolumeSizes[] = {64, 128, 256};
const int kImageSizes[] = {256, 512};

enum class TfVariant { Scene, Dense };
const TfVariant kTfVariants[] = {TfVariant::Scene, TfVariant::Dense};
// Opacity per unit distance: over the 200 mm of a built-in scene it alone leaves ~13 % of the
// light, so it keeps every region non-empty without ending rays early.
constexpr float kDenseOpacityFloor = 0.02f;

const char* toString(TfVariant v) {
  return v == TfVariant::Scene ? "scene" : "dense";
}

visopt::TransferFunction variantOf(visopt::TransferFunction tf, TfVariant variant) {
  if (variant == TfVariant::Dense) {
    for (visopt::OpacityPoint& p : tf.opacity) p.opacity = std::max(p.opacity, kDenseOpacityFloor);
    tf.name += "-dense";
  }
  return tf;
}

std::string sceneName() {
  const char* env = std::getenv("VISOPT_BENCH_SCENE");
  return env && *env ? std::string(env) : std::string("marschner-lobb");
}

std::string dumpDir() {
  const char* env = std::getenv("VISOPT_BENCH_DUMP");
  return env && *env ? std::string(env) : std::string();
}

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time consumed so far by all threads of this process.
double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Wall time and process CPU time of the timed part of a benchmark.
struct Timing {
  double wall = 0.0, cpu = 0.0;
};

// Counters common to both renderers, from the nominal sample count of one frame.
void setCounters(benchmark::State& state, const Timing& t, int64_t nominalPerFrame,
                 double threads) {
  const double frames = static_cast<double>(state.iterations());
  const double samples = static_cast<double>(nominalPerFrame) * frames;
  state.counters["Msps_core"] = samples / t.wall / threads * 1e-6;
  state.counters["Msps_core_cpu"] = samples / t.cpu * 1e-6;
  state.counters["cpu_util"] = t.cpu / (t.wall * threads);
  state.counters["ms_frame"] = t.wall / frames * 1e3;
  state.counters["threads"] = threads;
  state.counters["nominal_Msamples"] = static_cast<double>(nominalPerFrame) * 1e-6;
}

// Sample distance of both renderers: one smallest voxel spacing.
float sampleDistance(const visopt::GridSpec& grid) {
  return grid.minSpacing();
}

// The scene's default view, as visopt's Engine frames it on load.
visopt::Camera sceneCamera(const visopt::BuiltinScene& scene) {
  return visopt::Camera::orbitBounds(scene.volume.grid().worldBounds(), scene.azimuthDeg,
                                     scene.elevationDeg, scene.distanceInRadii);
}

// Sum over pixels of ceil(ray length inside `box` / step), rays through the pixel centres of a
// pinhole camera with vertical field of view camera.fovYDegrees (the convention of both visopt's
// camera and vtkCamera's default view angle).
int64_t nominalSamples(const visopt::Camera& camera, int width, int height,
                       const visopt::Bounds& box, float step) {
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tanY = std::tan(0.5f * glm::radians(camera.fovYDegrees));
  const float tanX = tanY * static_cast<float>(width) / static_cast<float>(height);
  int64_t total = 0;
  for (int py = 0; py < height; ++py)
    for (int px = 0; px < width; ++px) {
      const float u = (static_cast<float>(px) + 0.5f) / static_cast<float>(width) * 2.f - 1.f;
      const float v = (static_cast<float>(py) + 0.5f) / static_cast<float>(height) * 2.f - 1.f;
      const glm::vec3 dir = glm::normalize(forward + u * tanX * right + v * tanY * up);
      float t0 = 0.f, t1 = 3.0e38f;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(dir[a]) < 1e-12f) {
          if (camera.eye[a] < box.lo[a] || camera.eye[a] > box.hi[a]) t1 = -1.f;
          continue;
        }
        const float ta = (box.lo[a] - camera.eye[a]) / dir[a];
        const float tb = (box.hi[a] - camera.eye[a]) / dir[a];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
      }
      if (t1 > t0) total += static_cast<int64_t>(std::ceil((t1 - t0) / step));
    }
  return total;
}

visopt::RenderSettings settingsFor(int image) {
  visopt::RenderSettings s;
  s.width = s.height = image;
  s.stepFactor = 1.f;  // one smallest voxel spacing, as VTK's SampleDistance below
  return s;
}

// ---- visopt -----------------------------------------------------------------------------------

struct VisoptCase {
  int size = 0;
  visopt::Precision precision = visopt::Precision::FP32;
  TfVariant variant = TfVariant::Scene;
  std::unique_ptr<visopt::Engine> engine;
  visopt::TransferFunction sceneTf;
  int warmImage = 0;      // image size of the last warm-up render
  double lightMs = -1.0;  // T_L time of the first render with this transfer function
};

VisoptCase& visoptCase(int size, visopt::Precision precision, TfVariant variant) {
  static VisoptCase current;
  if (!current.engine || current.size != size || current.precision != precision) {
    current = VisoptCase{};  // release the previous volume first
    current.engine = std::make_unique<visopt::Engine>(precision);
    current.engine->loadBuiltinScene(sceneName(), size);
    current.sceneTf = current.engine->transferFunction();
    current.size = size;
    current.precision = precision;
  } else if (current.variant == variant) {
    return current;
  }
  current.engine->setTransferFunction(variantOf(current.sceneTf, variant));
  current.variant = variant;
  current.warmImage = 0;
  current.lightMs = -1.0;
  return current;
}

void benchVisopt(benchmark::State& state, int size, int image, TfVariant variant,
                 visopt::Precision precision) {
  try {
    VisoptCase& c = visoptCase(size, precision, variant);
    const visopt::RenderSettings settings = settingsFor(image);
    if (c.warmImage != image) {
      visopt::RenderStats warm;
      const visopt::Image img = c.engine->render(settings, &warm);
      if (c.lightMs < 0.0) c.lightMs = warm.lightMilliseconds;
      c.warmImage = image;
      if (!dumpDir().empty())
        visopt::writePng(img, dumpDir() + "/visopt-" + std::to_string(size) + "-" +
                                  std::to_string(image) + "-" + toString(variant) + "-" +
                                  visopt::toString(precision) + ".png");
    }
    const visopt::GridSpec& grid = c.engine->volume().grid();
    const int64_t nominal =
        nominalSamples(c.engine->camera(), image, image, grid.worldBounds(), sampleDistance(grid));
    const double threads = tbb::info::default_concurrency();

    Timing t;
    int64_t taken = 0;
    for (auto _ : state) {
      visopt::RenderStats stats;
      const double cpu0 = processCpuSeconds();
      const auto start = Clock::now();
      visopt::Image img = c.engine->render(settings, &stats);
      const double s = secondsSince(start);
      t.cpu += processCpuSeconds() - cpu0;
      benchmark::DoNotOptimize(img.pixels.data());
      state.SetIterationTime(s);
      t.wall += s;
      taken += stats.samples;
    }
    setCounters(state, t, nominal, threads);
    state.counters["Msps_core_taken"] = static_cast<double>(taken) / t.wall / threads * 1e-6;
    state.counters["Msps_core_taken_cpu"] = static_cast<double>(taken) / t.cpu * 1e-6;
    state.counters["light_ms"] = c.lightMs;
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

// ---- VTK --------------------------------------------------------------------------------------

struct VtkCase {
  int size = 0;
  TfVariant variant = TfVariant::Scene;
  int warmImage = 0;
  visopt::Camera camera;
  visopt::GridSpec grid;
  visopt::TransferFunction sceneTf;
  vtkNew<vtkImageData> data;
  vtkNew<vtkPiecewiseFunction> opacity;
  vtkNew<vtkColorTransferFunction> color;
  vtkNew<vtkVolumeProperty> property;
  vtkNew<vtkFixedPointVolumeRayCastMapper> mapper;
  vtkNew<vtkVolume> volume;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkRenderWindow> window;
};

// The visopt volume as a vtkImageData of float data values (valueMin + t * range), same origin
// and spacing; visopt's x index runs fastest, as VTK's does.
void copyVolume(const visopt::Volume& volume, vtkImageData* out) {
  const visopt::GridSpec& g = volume.grid();
  if (g.direction != glm::mat3(1.f))
    throw std::runtime_error("the VTK comparison needs an axis-aligned volume");
  out->SetDimensions(g.dims.x, g.dims.y, g.dims.z);
  out->SetSpacing(g.spacing.x, g.spacing.y, g.spacing.z);
  out->SetOrigin(g.origin.x, g.origin.y, g.origin.z);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName("scalars");
  scalars->SetNumberOfComponents(1);
  scalars->SetNumberOfTuples(static_cast<vtkIdType>(g.voxelCount()));
  float* dst = scalars->GetPointer(0);
  const size_t n = g.voxelCount();
  for (size_t i = 0; i < n; ++i)
    dst[i] = static_cast<float>(volume.toValue(volume.normalized.get(i)));
  out->GetPointData()->SetScalars(scalars);
}

// The visopt transfer function as VTK's: the same points in data units, and the same opacity
// semantics (alpha is the opacity of a slab of thickness unitDistance).
void copyTransferFunction(const visopt::TransferFunction& tf, const visopt::GridSpec& grid,
                          VtkCase& c) {
  c.opacity->RemoveAllPoints();
  for (const visopt::OpacityPoint& p : tf.opacity) c.opacity->AddPoint(p.value, p.opacity);
  c.color->RemoveAllPoints();
  for (const visopt::ColorPoint& p : tf.color)
    c.color->AddRGBPoint(p.value, p.rgb.r, p.rgb.g, p.rgb.b);
  c.property->SetScalarOpacity(c.opacity);
  c.property->SetColor(c.color);
  c.property->SetScalarOpacityUnitDistance(tf.unitDistance > 0.f ? tf.unitDistance
                                                                 : grid.minSpacing());
  c.property->SetInterpolationTypeToLinear();
  c.property->ShadeOn();  // default ambient 0.1, diffuse 0.7, specular 0.2, power 10
}

std::unique_ptr<VtkCase> makeVtkCase(int size, TfVariant variant) {
  auto c = std::make_unique<VtkCase>();
  const visopt::BuiltinScene scene =
      visopt::makeBuiltinScene(sceneName(), size, visopt::Precision::FP32);
  c->size = size;
  c->variant = variant;
  c->grid = scene.volume.grid();
  c->camera = sceneCamera(scene);
  c->sceneTf = scene.transferFunction;
  copyVolume(scene.volume, c->data);
  copyTransferFunction(variantOf(c->sceneTf, variant), c->grid, *c);

  const double step = sampleDistance(c->grid);
  c->mapper->SetInputData(c->data);
  c->mapper->SetBlendModeToComposite();
  c->mapper->SetAutoAdjustSampleDistances(0);
  c->mapper->SetLockSampleDistanceToInputSpacing(0);
  c->mapper->SetSampleDistance(static_cast<float>(step));
  c->mapper->SetInteractiveSampleDistance(static_cast<float>(step));
  c->mapper->SetImageSampleDistance(1.f);  // one ray per pixel
  c->mapper->SetNumberOfThreads(vtkMultiThreader::GetGlobalDefaultNumberOfThreads());
  c->volume->SetMapper(c->mapper);
  c->volume->SetProperty(c->property);

  c->renderer->AddVolume(c->volume);
  c->renderer->SetBackground(0.06, 0.065, 0.075);
  vtkCamera* cam = c->renderer->GetActiveCamera();
  cam->SetPosition(c->camera.eye.x, c->camera.eye.y, c->camera.eye.z);
  cam->SetFocalPoint(c->camera.target.x, c->camera.target.y, c->camera.target.z);
  cam->SetViewUp(c->camera.up.x, c->camera.up.y, c->camera.up.z);
  cam->SetViewAngle(c->camera.fovYDegrees);  // vertical, as visopt's
  c->renderer->ResetCameraClippingRange();

  c->window->SetOffScreenRendering(1);
  c->window->SetMultiSamples(0);
  c->window->AddRenderer(c->renderer);
  return c;
}

void dumpVtkImage(VtkCase& c, int image) {
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(c.window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkImageData* rgb = grab->GetOutput();
  auto* bytes = static_cast<unsigned char*>(rgb->GetScalarPointer());
  int dims[3];
  rgb->GetDimensions(dims);
  visopt::Image out(dims[0], dims[1]);
  auto linear = [](unsigned char v) {
    const float c8 = static_cast<float>(v) / 255.f;
    return c8 <= 0.04045f ? c8 / 12.92f : std::pow((c8 + 0.055f) / 1.055f, 2.4f);
  };
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const unsigned char* p = bytes + 3 * (static_cast<size_t>(y) * dims[0] + x);
      out.at(x, dims[1] - 1 - y) = glm::vec3(linear(p[0]), linear(p[1]), linear(p[2]));
    }
  visopt::writePng(out, dumpDir() + "/vtk-" + std::to_string(c.size) + "-" + std::to_string(image) +
                            "-" + toString(c.variant) + ".png");
}

VtkCase& vtkCase(int size, TfVariant variant) {
  static std::unique_ptr<VtkCase> current;
  if (!current || current->size != size) {
    current.reset();  // release the previous volume and window first
    current = makeVtkCase(size, variant);
  } else if (current->variant != variant) {
    copyTransferFunction(variantOf(current->sceneTf, variant), current->grid, *current);
    current->variant = variant;
    current->warmImage = 0;
  }
  return *current;
}

void benchVtk(benchmark::State& state, int size, int image, TfVariant variant) {
  if (!std::getenv("DISPLAY")) {
    state.SkipWithError("no DISPLAY: VTK's render window needs X; run under xvfb-run -a");
    return;
  }
  try {
    VtkCase& c = vtkCase(size, variant);
    if (c.warmImage != image) {
      // The first render of a size builds the gradients, normals and shading tables.
      c.window->SetSize(image, image);
      c.renderer->ResetCameraClippingRange();
      c.window->Render();
      c.warmImage = image;
      if (!dumpDir().empty()) dumpVtkImage(c, image);
    }
    const int64_t nominal =
        nominalSamples(c.camera, image, image, c.grid.worldBounds(), sampleDistance(c.grid));
    const double threads = c.mapper->GetNumberOfThreads();

    Timing t;
    double mapperSeconds = 0.0;
    for (auto _ : state) {
      const double cpu0 = processCpuSeconds();
      const auto start = Clock::now();
      c.window->Render();
      const double s = secondsSince(start);
      t.cpu += processCpuSeconds() - cpu0;
      state.SetIterationTime(s);
      t.wall += s;
      mapperSeconds += static_cast<double>(c.mapper->GetEstimatedRenderTime(c.renderer, c.volume));
    }
    setCounters(state, t, nominal, threads);
    const double frames = static_cast<double>(state.iterations());
    state.counters["Msps_core_mapper"] =
        mapperSeconds > 0.0 ? static_cast<double>(nominal) * frames / mapperSeconds / threads * 1e-6
                            : 0.0;
    state.counters["mapper_ms"] = mapperSeconds / frames * 1e3;
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void registerBenchmarks() {
  // Grouped by volume size, then transfer function, so each volume is built once per renderer
  // and precision and each transfer function's tables once per volume.
  for (int size : kVolumeSizes)
    for (TfVariant tf : kTfVariants) {
      const std::string tail = "/tf:" + std::string(toString(tf));
      for (visopt::Precision p : {visopt::Precision::FP32, visopt::Precision::FP16})
        for (int image : kImageSizes)
          benchmark::RegisterBenchmark(("visopt/size:" + std::to_string(size) + "/image:" +
                                        std::to_string(image) + tail + "/" + visopt::toString(p))
                                           .c_str(),
                                       benchVisopt, size, image, tf, p)
              ->UseManualTime()
              ->Unit(benchmark::kMillisecond);
      for (int image : kImageSizes)
        benchmark::RegisterBenchmark(("vtk_fixed_point/size:" + std::to_string(size) +
                                      "/image:" + std::to_string(image) + tail)
                                         .c_str(),
                                     benchVtk, size, image, tf)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond);
    }
}

}  // namespace

int main(int argc, char** argv) {
  registerBenchmarks();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::AddCustomContext("visopt_backend", visopt::backendDescription());
  benchmark::AddCustomContext("visopt_threads", std::to_string(tbb::info::default_concurrency()));
  benchmark::AddCustomContext("vtk_threads",
                              std::to_string(vtkMultiThreader::GetGlobalDefaultNumberOfThreads()));
  benchmark::AddCustomContext("scene", sceneName());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
