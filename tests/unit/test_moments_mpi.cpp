// visopt-moments-mpi (issue 17, item 5) end to end under mpirun: 1, 2 and 3 ranks, and ranks that
// read their slices in several slabs under --memory-limit, write the moment image that
// generateMomentImage makes of the whole volume in one process (counts and bounds exactly,
// moments to 1e-6), for a built-in scene, a raw file whose value range spans the ranks, and a
// real CT when the datasets are there; a broken file fails on every rank without an output.
// Skipped with a message when the build found no MPI.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "moment_image_checks.h"
#include "visopt/moment_image.h"
#include "visopt/scenes.h"
#include "visopt/volume_io.h"

namespace visopt {
namespace {

namespace fs = std::filesystem;

const std::string kTool = VISOPT_MOMENTS_MPI;
const std::string kMpiexec = VISOPT_MPIEXEC;

std::string tmp(const std::string& name) {
  return std::string(VISOPT_TEST_TMP) + "/mpi_" + name;
}

// Runs the tool on `ranks` processes; returns its exit status.
int runTool(int ranks, const std::string& args, const std::string& log) {
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  const std::string cmd = kMpiexec + " --oversubscribe --bind-to none -n " + std::to_string(ranks) +
                          " " + kTool + " generate " + args + " > " + log + " 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The image against the reference, and the view sees the volume (so the comparison means
// something).
// The view must see the volume first: two empty images would compare equal.
void expectSameImage(const MomentImage& a, const MomentImage& b, const std::string& what) {
  size_t hit = 0;
  for (size_t p = 0; p < a.pixelCount(); ++p) hit += a.counts[p] > 0;
  ASSERT_GT(hit, a.pixelCount() / 4) << what << ": the view must see the volume";
  testing::expectSameMomentImage(a, b, what);
}

class MomentsMpi : public ::testing::Test {
 protected:
  void SetUp() override {
    if (kTool.empty() || kMpiexec.empty())
      GTEST_SKIP() << "this build found no MPI: visopt-moments-mpi is not built";
  }
};

constexpr float kAz = 30.f, kEl = 25.f, kDist = 2.6f;
const std::string kCamera = "--camera 30,25,2.6";

TEST_F(MomentsMpi, OneTwoAndThreeRanksWriteTheSingleProcessImageOfAScene) {
  const BuiltinScene s = makeBuiltinScene("marschner-lobb", 40, Precision::FP32);
  MomentImageSettings settings;
  settings.width = 40;
  settings.height = 32;
  const Camera cam = Camera::orbitBounds(s.volume.grid().worldBounds(), kAz, kEl, kDist);
  const MomentImage reference = generateMomentImage(s.volume, cam, settings);
  for (int ranks : {1, 2, 3}) {
    const std::string out = tmp("scene_" + std::to_string(ranks) + ".vmi");
    const std::string log = tmp("scene_" + std::to_string(ranks) + ".log");
    ASSERT_EQ(runTool(ranks,
                      "--scene builtin:marschner-lobb --resolution 40 --size 40x32 " + kCamera +
                          " --out " + out,
                      log),
              0)
        << slurp(log);
    expectSameImage(readMomentImage(out), reference, std::to_string(ranks) + " ranks");
  }
}

// An int16 raw volume whose values rise along z: each rank's own range is a part of the whole,
// so the normalisation must use the range over all ranks.
std::string writeRampRaw(const std::string& name, int nx, int ny, int nz, bool truncate) {
  const std::string path = tmp(name + ".raw");
  std::vector<int16_t> v(size_t(nx) * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double x = (i - nx / 2.0) / nx, y = (j - ny / 2.0) / ny;
        const double blob = std::exp(-20.0 * (x * x + y * y));
        v[(size_t(k) * ny + j) * nx + i] = int16_t(-1000 + 40 * k + std::lround(800 * blob));
      }
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(v.data()),
             std::streamsize(v.size() * 2 - (truncate ? 100 : 0)));
  std::ofstream(path + ".json") << "{\"dims\": [" << nx << ", " << ny << ", " << nz
                                << "], \"type\": \"int16\", \"spacing\": [1.0, 1.0, 1.5]}";
  return path;
}

TEST_F(MomentsMpi, RanksReadingSlabsOfAFileUnderAMemoryLimitWriteTheSingleProcessImage) {
  const int nx = 36, ny = 30, nz = 27;
  const std::string raw = writeRampRaw("ramp", nx, ny, nz, false);
  const Volume v = readVolume(raw, Precision::FP32);
  MomentImageSettings settings;
  settings.width = 36;
  settings.height = 36;
  const Camera cam = Camera::orbitBounds(v.grid().worldBounds(), kAz, kEl, kDist);
  const MomentImage reference = generateMomentImage(v, cam, settings);
  // A slice of values as read and normalised is nx * ny * 12 bytes; the halo is 2 slices each
  // side: this limit holds 8 slices, so each rank's share is read in slabs of 4 owned slices.
  const size_t limit = size_t(nx) * ny * 12 * 8;
  struct Case {
    int ranks;
    std::string extra;
  };
  for (const Case& c : {Case{1, ""}, Case{2, ""}, Case{3, ""},
                        Case{2, " --memory-limit " + std::to_string(limit)}}) {
    const std::string tag = std::to_string(c.ranks) + (c.extra.empty() ? "" : "_limited");
    const std::string out = tmp("ramp_" + tag + ".vmi"), log = tmp("ramp_" + tag + ".log");
    ASSERT_EQ(
        runTool(c.ranks,
                "--volume " + raw + " --size 36x36 " + kCamera + c.extra + " --json --out " + out,
                log),
        0)
        << slurp(log);
    expectSameImage(readMomentImage(out), reference, tag + " ranks");
    const std::string report = slurp(log);
    if (!c.extra.empty()) {
      EXPECT_NE(report.find("\"slabs\": 4"), std::string::npos)
          << "each rank's 13-14 slices read in slabs of 4:\n"
          << report;
    } else if (c.ranks == 2) {
      // Without a limit each share is read once, with its halo: [0, 13) + 2 and 2 + [13, 27).
      EXPECT_NE(report.find("\"slices_read\": 15"), std::string::npos) << report;
      EXPECT_NE(report.find("\"slices_read\": 16"), std::string::npos) << report;
    }
  }
}

TEST_F(MomentsMpi, ARealCtSplitAcrossRanksWritesTheSingleProcessImage) {
  const std::string ct = std::string(VISOPT_DATA_DIR) + "/Cranium.raw";
  if (!fs::exists(ct)) GTEST_SKIP() << ct << " is absent (datasets-scripts/fetch_datasets.sh)";
  const Volume v = readVolume(ct, Precision::FP32);
  MomentImageSettings settings;
  settings.width = 64;
  settings.height = 64;
  const Camera cam = Camera::orbitBounds(v.grid().worldBounds(), kAz, kEl, kDist);
  const MomentImage reference = generateMomentImage(v, cam, settings);
  const std::string out = tmp("ct.vmi"), log = tmp("ct.log");
  ASSERT_EQ(runTool(3, "--volume " + ct + " --size 64x64 " + kCamera + " --out " + out, log), 0)
      << slurp(log);
  expectSameImage(readMomentImage(out), reference, "Cranium CT, 3 ranks");
}

TEST_F(MomentsMpi, ATruncatedFileFailsOnEveryRankWithoutAnOutput) {
  const std::string raw = writeRampRaw("truncated", 20, 20, 12, true);
  const std::string out = tmp("truncated.vmi"), log = tmp("truncated.log");
  fs::remove(out);
  EXPECT_EQ(runTool(2, "--volume " + raw + " --size 16x16 --out " + out, log), 2) << slurp(log);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_NE(slurp(log).find(raw), std::string::npos) << "the message names the file";
  EXPECT_EQ(runTool(2, "--scene builtin:marschner-lobb --memory-limit 10 --out " + out, log), 1)
      << slurp(log);
  EXPECT_EQ(runTool(1, "--scene builtin:nonesuch --out " + out, log), 1) << slurp(log);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace visopt
