// Times sdfFromIsovalue (the base SDF phi0 of an isosurface context, Himmler & Günther 2026, Eq. 18
// from s(x) - iso) on a volume file, and optionally writes phi (fp32, voxels in x-fastest order,
// world units) to a raw file, or compares it with such a file written earlier: the mean and max
// |phi - phi_other| in voxels over the whole grid and over the band within 3 voxels of the
// surface in both.
//
// Usage: sdf_from_isovalue VOLUME ISOVALUE [inside-high|inside-low] [fp32|fp16]
//                          [--write FILE | --compare FILE] [--repeat N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "optimize/level_set.h"
#include "visopt/exec.h"
#include "visopt/volume_io.h"

namespace {

using Clock = std::chrono::steady_clock;

int run(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: sdf_from_isovalue VOLUME ISOVALUE [inside-high|inside-low] [fp32|fp16] "
                 "[--write FILE | --compare FILE] [--repeat N]\n");
    return 1;
  }
  const std::string path = argv[1];
  const double iso = std::atof(argv[2]);
  bool insideHigh = true;
  visopt::Precision precision = visopt::Precision::FP32;
  std::string writeFile, compareFile;
  int repeat = 1;
  for (int a = 3; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "inside-low") insideHigh = false;
    if (arg == "fp16") precision = visopt::Precision::FP16;
    if (arg == "--write" && a + 1 < argc) writeFile = argv[++a];
    if (arg == "--compare" && a + 1 < argc) compareFile = argv[++a];
    if (arg == "--repeat" && a + 1 < argc) repeat = std::max(1, std::atoi(argv[++a]));
  }
  const visopt::Volume volume = visopt::readVolume(path, visopt::Precision::FP32);
  const visopt::GridSpec& g = volume.grid();
  std::printf("%s: %dx%dx%d, spacing %.3g %.3g %.3g, iso %g, %s, %s\n", path.c_str(), g.dims.x,
              g.dims.y, g.dims.z, double(g.spacing.x), double(g.spacing.y), double(g.spacing.z),
              iso, visopt::toString(precision), visopt::backendDescription().c_str());
  visopt::LevelSetSettings settings;
  visopt::Field3D phi;
  double best = 1e30;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = Clock::now();
    phi = visopt::sdfFromIsovalue(volume, iso, insideHigh, settings, precision, nullptr);
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  std::printf("sdfFromIsovalue: %.3f s (best of %d)\n", best, repeat);

  std::vector<float> values(phi.size());
  for (size_t i = 0; i < values.size(); ++i) values[i] = phi.get(i);
  if (!writeFile.empty()) {
    std::ofstream(writeFile, std::ios::binary)
        .write(reinterpret_cast<const char*>(values.data()),
               std::streamsize(values.size() * sizeof(float)));
  }
  if (!compareFile.empty()) {
    std::vector<float> other(values.size());
    std::ifstream in(compareFile, std::ios::binary);
    in.read(reinterpret_cast<char*>(other.data()), std::streamsize(other.size() * sizeof(float)));
    if (!in) throw std::runtime_error("cannot read " + compareFile + " at this grid's size");
    const double h = g.minSpacing();
    double sum = 0.0, worst = 0.0, bandSum = 0.0, bandWorst = 0.0;
    size_t band = 0, signFlips = 0;
    for (size_t i = 0; i < values.size(); ++i) {
      const double e = std::abs(double(values[i]) - double(other[i])) / h;
      sum += e;
      worst = std::max(worst, e);
      if ((values[i] < 0.f) != (other[i] < 0.f)) ++signFlips;
      if (std::abs(other[i]) <= 3.0 * h && std::abs(values[i]) <= 3.0 * h) {
        bandSum += e;
        bandWorst = std::max(bandWorst, e);
        ++band;
      }
    }
    std::printf(
        "against %s: all voxels mean %.4f max %.3f voxel; band |phi| <= 3 voxels in both (%zu): "
        "mean %.4f max %.3f voxel; sign differs at %zu voxels\n",
        compareFile.c_str(), sum / double(values.size()), worst, band,
        band ? bandSum / double(band) : 0.0, bandWorst, signFlips);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdf_from_isovalue: %s\n", e.what());
    return 1;
  }
}
