// visopt-moments-mpi generate: a moment image (Rapp, Peters, Dachsbacher 2022) generated across
// MPI ranks, for volumes no single process may hold. The volume's z slices are shared out in
// contiguous ranges, one per rank; a rank reads only its range (in slabs no larger than
// --memory-limit, each with the halo its rays' last samples need), marches the parts of every
// pixel's ray its slabs own (visopt/moment_image.h, MomentPartials), and the partial moments and
// bounds are reduced (sum, min, max) to rank 0, which finishes and writes the .vmi. The result is
// `visopt moments generate`'s to double round-off of the sums.
//
// Exit codes as the visopt CLI: 0 success, 1 usage error, 2 bad input, 3 other failures; every
// rank returns the same code, and the rank that met a problem prints it.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "../cli/cli_common.h"
#include "visopt/error.h"
#include "visopt/moment_image.h"
#include "visopt/scenes.h"
#include "visopt/value_normalization.h"
#include "visopt/volume_slabs.h"

namespace {

using namespace visopt;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

struct Options {
  std::string volume, scene, camera, size = "512x512", out, memoryLimit;
  int resolution = 128, threads = 0;
  MomentImageSettings settings;
  bool json = false;
};

// "512M", "2G", "65536": bytes.
size_t parseBytes(const std::string& text) {
  if (text.empty()) return 0;
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  double unit = 1.0;
  const std::string suffix = text.substr(used);
  if (suffix == "K" || suffix == "k")
    unit = 1024.0;
  else if (suffix == "M")
    unit = 1024.0 * 1024.0;
  else if (suffix == "G")
    unit = 1024.0 * 1024.0 * 1024.0;
  else if (!suffix.empty())
    used = 0;
  if (used == 0 || !(v > 0.0) || !std::isfinite(v * unit))
    throw Error(ErrorKind::Usage,
                "--memory-limit must be a positive size such as 65536, 64M or 2G, not " + text);
  return size_t(std::min(v * unit, 1e18));
}

// What a rank reads its slices from: a volume file by slabs, or a built-in scene (generated whole
// on every rank and cut: scenes are the small test cases; only files are read in part).
struct Source {
  std::optional<VolumeSlabReader> file;
  std::optional<BuiltinScene> scene;
  std::string name;

  const GridSpec& grid() const { return file ? file->grid() : scene->volume.grid(); }
  // Physical values of slices [z0, z1) (a scene's are already normalised: its range is [0, 1]
  // in the sense of valueMin/valueMax applied below).
  std::vector<double> read(int z0, int z1) const {
    if (file) return file->readSlices(z0, z1);
    const Field3D& f = scene->volume.normalized;
    const size_t plane = size_t(grid().dims.x) * size_t(grid().dims.y);
    std::vector<double> out(plane * size_t(z1 - z0));
    for (size_t i = 0; i < out.size(); ++i) out[i] = double(f.get(size_t(z0) * plane + i));
    return out;
  }
};

// The value range over every rank's slices: the normalisation readVolume applies to a whole
// file (NaN and Inf are refused by the reader, as readVolume refuses them).
struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
};

// One rank's contiguous share of the slices, cut into slabs of at most `depth` owned slices.
struct Share {
  int begin = 0, end = 0;
};
Share shareOf(int slices, int rank, int ranks) {
  return {int(int64_t(slices) * rank / ranks), int(int64_t(slices) * (rank + 1) / ranks)};
}

// Slices [z0, z1) normalised as readVolume normalises the whole volume; `v` holds their values
// as Source::read gives them.
Field3D normalisedSlab(const Source& src, const std::vector<double>& v, int z0, int z1, double lo,
                       double hi) {
  GridSpec g = src.grid();
  g.dims.z = z1 - z0;
  Field3D slab("moment slab", g, Precision::FP32);
  if (src.scene) {  // already normalised
    for (size_t i = 0; i < v.size(); ++i) slab.set(i, float(v[i]));
    return slab;
  }
  // readVolume's normalisation, so that the slab equals its field.
  const ValueNormalization normalize(lo, hi);
  for (size_t i = 0; i < v.size(); ++i) slab.set(i, normalize(v[i]));
  return slab;
}

int exitCodeOf(const Error& e) {
  switch (e.kind()) {
    case ErrorKind::Usage:
      return visopt::cli::kUsage;
    case ErrorKind::BadInput:
      return visopt::cli::kBadInput;
    default:
      return visopt::cli::kFailure;
  }
}

// Runs `f` on every rank; when it throws on any, every rank returns that code (the largest).
template <class F>
int collectively(int rank, F&& f) {
  int code = 0;
  try {
    f();
  } catch (const Error& e) {
    std::fprintf(stderr, "visopt-moments-mpi (rank %d): %s\n", rank, e.what());
    code = exitCodeOf(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "visopt-moments-mpi (rank %d): %s\n", rank, e.what());
    code = visopt::cli::kFailure;
  }
  int worst = 0;
  MPI_Allreduce(&code, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return worst;
}

int run(int rank, int ranks, Options& o, int threads) {
  Source src;
  Camera camera;
  double valueMin = 0.0, valueMax = 1.0;
  size_t limit = 0;
  if (int code = collectively(rank, [&] {
        if (!std::filesystem::path(o.out).has_filename())
          throw Error(ErrorKind::Usage, "--out must name a file");
        const glm::ivec2 size = visopt::cli::parseSize(o.size);
        o.settings.width = size.x;
        o.settings.height = size.y;
        checkMomentImageSettings(o.settings);
        if (o.settings.uncertaintyQuantile > 0.f)
          throw Error(ErrorKind::Usage,
                      "the uncertainty needs each whole ray; use `visopt "
                      "moments generate --uncertainty` on one machine");
        limit = parseBytes(o.memoryLimit);
        OrbitView view = kDefaultVolumeView;
        if (!o.volume.empty()) {
          src.file.emplace(o.volume);
          src.name = o.volume;
        } else {
          if (o.scene.rfind("builtin:", 0) != 0)
            throw Error(ErrorKind::Usage, "--scene must be builtin:NAME, not " + o.scene);
          src.scene.emplace(makeBuiltinScene(o.scene.substr(8), o.resolution, Precision::FP32));
          src.name = o.scene;
          valueMin = src.scene->volume.valueMin;
          valueMax = src.scene->volume.valueMax;
          view = {src.scene->azimuthDeg, src.scene->elevationDeg, src.scene->distanceInRadii};
        }
        if (!o.camera.empty()) {
          const glm::vec3 c = visopt::cli::parseTriple(o.camera, "--camera");
          checkOrbit(c.x, c.y, c.z, "--camera");
          view = {c.x, c.y, c.z};
        }
        camera = Camera::orbitBounds(src.grid().worldBounds(), view.azimuthDeg, view.elevationDeg,
                                     view.distanceInRadii);
        checkCamera(camera, src.grid().worldBounds(), "--camera");
      }))
    return code;

  const GridSpec& grid = src.grid();
  const int nz = grid.dims.z, halo = momentSlabHalo(o.settings);
  const size_t plane = size_t(grid.dims.x) * size_t(grid.dims.y);
  // A slab in memory: its values as read (8 bytes) and normalised (4 bytes) per voxel.
  const size_t bytesPerSlice = plane * 12;
  int depth = nz;
  if (limit > 0) {
    const int64_t fits = int64_t(limit / bytesPerSlice) - 2 * halo;
    if (fits < 1) {
      if (rank == 0)
        std::fprintf(stderr,
                     "visopt-moments-mpi: --memory-limit %s holds less than one slice of %s and "
                     "its halo (%zu bytes needed)\n",
                     o.memoryLimit.c_str(), src.name.c_str(), size_t(1 + 2 * halo) * bytesPerSlice);
      return visopt::cli::kUsage;
    }
    depth = int(std::min<int64_t>(fits, nz));
  }
  const Share share = shareOf(nz, rank, ranks);

  // The slices a slab reads: its own and the halo on either side.
  auto slabBegin = [&](int z) { return std::max(0, z - halo); };
  auto slabEnd = [&](int z) { return std::min(nz, std::min(share.end, z + depth) + halo); };
  // A share that is one slab is read once: the range pass reads it with its halo and keeps the
  // values for the march (the halo's slices are other ranks' own, so they leave the range over
  // all ranks as it is). A share of several slabs is read twice, as no more fits.
  const bool oneSlab = share.end - share.begin <= depth;
  std::vector<double> kept;
  int slicesRead = 0;  // over both passes, for the report
  auto read = [&](int z0, int z1) {
    slicesRead += z1 - z0;
    return src.read(z0, z1);
  };

  // The value range over all ranks (files only; a scene's is its own).
  const auto tRange = Clock::now();
  Range mine;
  if (int code = collectively(rank, [&] {
        if (!src.file) return;
        for (int z = share.begin; z < share.end; z += depth) {
          std::vector<double> v =
              oneSlab ? read(slabBegin(z), slabEnd(z)) : read(z, std::min(share.end, z + depth));
          for (double x : v) {
            mine.lo = std::min(mine.lo, x);
            mine.hi = std::max(mine.hi, x);
          }
          if (oneSlab) kept = std::move(v);
        }
      }))
    return code;
  if (src.file) {
    Range all;
    MPI_Allreduce(&mine.lo, &all.lo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&mine.hi, &all.hi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    valueMin = all.lo;
    valueMax = all.hi;
  }
  const double rangeMs = msSince(tRange);

  // This rank's slabs, each read with its halo and marched.
  MomentPartials partials;
  double readMs = 0.0, marchMs = 0.0;
  int slabs = 0;
  size_t largestSlab = 0;
  if (int code = collectively(rank, [&] {
        partials = emptyMomentPartials(o.settings);
        for (int z = share.begin; z < share.end; z += depth) {
          const int own1 = std::min(share.end, z + depth);
          const int z0 = slabBegin(z), z1 = slabEnd(z);
          const auto tr = Clock::now();
          const std::vector<double> values = kept.empty() ? read(z0, z1) : std::move(kept);
          kept = {};
          const Field3D slab = normalisedSlab(src, values, z0, z1, valueMin, valueMax);
          readMs += msSince(tr);
          largestSlab = std::max(largestSlab, size_t(z1 - z0) * bytesPerSlice);
          addMomentSlab(partials, slab, z0, z, own1, grid, camera, o.settings, &marchMs);
          ++slabs;
        }
      }))
    return code;

  // The reduction: each rank receives the sums of the raw moments and the min and max of the
  // bounds of its share of the pixels (runs of whole pixels, in order), finishes them (Eq. 5,
  // §3.5's counts: per pixel, so the ranks share that work too), and rank 0 gathers the results.
  const size_t pixels = size_t(o.settings.width) * size_t(o.settings.height);
  const size_t stride = size_t(o.settings.moments) + 1;
  // The shares are runs of whole rows with about as many hit pixels each (a hit pixel's count
  // costs a bisection; a missed one nothing): hits per row summed over the ranks' partials (a
  // ray crossing slabs counts once per slab, close enough to balance).
  const int width = o.settings.width, height = o.settings.height;
  std::vector<double> rowHits(size_t(height), 0.0), allRowHits(size_t(height), 0.0);
  for (size_t p = 0; p < pixels; ++p)
    if (partials.lower[p] <= partials.upper[p]) rowHits[p / size_t(width)] += 1.0;
  MPI_Allreduce(rowHits.data(), allRowHits.data(), height, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  std::vector<size_t> firstRow(size_t(ranks) + 1, size_t(height));
  {
    double total = 0.0;
    for (double h : allRowHits) total += h + 1e-3;  // rows without hits still cost a little
    double before = 0.0;
    int r = 1;
    firstRow[0] = 0;
    for (int row = 0; row < height && r < ranks; ++row) {
      before += allRowHits[size_t(row)] + 1e-3;
      while (r < ranks && before >= total * double(r) / double(ranks))
        firstRow[size_t(r++)] = size_t(row) + 1;
    }
  }
  auto firstPixel = [&](int r) { return firstRow[size_t(r)] * size_t(width); };
  size_t largestShare = 0;
  for (int r = 0; r < ranks; ++r)
    largestShare = std::max(largestShare, firstPixel(r + 1) - firstPixel(r));
  if (largestShare * stride > size_t(std::numeric_limits<int>::max())) {
    if (rank == 0)
      std::fprintf(stderr,
                   "visopt-moments-mpi: %zu pixels of %zu moments are too many for %d "
                   "ranks (a rank's share must stay below 2^31 moments): use more ranks\n",
                   pixels, stride, ranks);
    return visopt::cli::kUsage;
  }
  const size_t rankCount = size_t(ranks);
  std::vector<int> momentCounts(rankCount), pixelCounts(rankCount), pixelOffsets(rankCount);
  for (int r = 0; r < ranks; ++r) {
    pixelCounts[size_t(r)] = int(firstPixel(r + 1) - firstPixel(r));
    pixelOffsets[size_t(r)] = int(firstPixel(r));
    momentCounts[size_t(r)] = int(size_t(pixelCounts[size_t(r)]) * stride);
  }
  const size_t mineN = size_t(pixelCounts[size_t(rank)]);
  const auto tReduce = Clock::now();
  std::vector<double> sums(std::max<size_t>(mineN * stride, 1));
  std::vector<float> lows(std::max<size_t>(mineN, 1)), highs(std::max<size_t>(mineN, 1));
  MPI_Reduce_scatter(partials.moments.data(), sums.data(), momentCounts.data(), MPI_DOUBLE, MPI_SUM,
                     MPI_COMM_WORLD);
  MPI_Reduce_scatter(partials.lower.data(), lows.data(), pixelCounts.data(), MPI_FLOAT, MPI_MIN,
                     MPI_COMM_WORLD);
  MPI_Reduce_scatter(partials.upper.data(), highs.data(), pixelCounts.data(), MPI_FLOAT, MPI_MAX,
                     MPI_COMM_WORLD);
  partials = MomentPartials();  // the whole image's partials are no longer needed
  const double reduceMs = msSince(tReduce);

  const auto tCount = Clock::now();
  MomentPixels finished;
  double countMs = 0.0;
  if (int code = collectively(rank, [&] {
        finished =
            finishMomentPixels(std::span<const double>(sums.data(), mineN * stride),
                               std::span<const float>(lows.data(), mineN),
                               std::span<const float>(highs.data(), mineN), o.settings, &countMs);
      }))
    return code;

  // Gather the finished pixels to rank 0, in pixel order.
  const auto tGather = Clock::now();
  MomentPixels whole;
  if (rank == 0) {
    whole.counts.resize(pixels);
    whole.lower.resize(pixels);
    whole.upper.resize(pixels);
  }
  MPI_Gatherv(finished.counts.data(), int(mineN), MPI_UINT8_T, whole.counts.data(),
              pixelCounts.data(), pixelOffsets.data(), MPI_UINT8_T, 0, MPI_COMM_WORLD);
  MPI_Gatherv(finished.lower.data(), int(mineN), MPI_FLOAT, whole.lower.data(), pixelCounts.data(),
              pixelOffsets.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
  MPI_Gatherv(finished.upper.data(), int(mineN), MPI_FLOAT, whole.upper.data(), pixelCounts.data(),
              pixelOffsets.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
  const int stored = int(finished.moments.size());
  std::vector<int> storedCounts(rankCount), storedOffsets(rankCount, 0);
  MPI_Gather(&stored, 1, MPI_INT, storedCounts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    size_t total = 0;
    for (int r = 0; r < ranks; ++r) {
      storedOffsets[size_t(r)] = int(total);
      total += size_t(storedCounts[size_t(r)]);
    }
    whole.moments.resize(total);
  }
  MPI_Gatherv(finished.moments.data(), stored, MPI_FLOAT, whole.moments.data(), storedCounts.data(),
              storedOffsets.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
  const double gatherMs = msSince(tGather);
  const double countWallMs = msSince(tCount) - gatherMs;

  // Every rank's timings for the report.
  constexpr int kReported = 5;
  const double times[kReported] = {readMs, marchMs, double(slabs), countMs, double(slicesRead)};
  std::vector<double> all(size_t(ranks) * kReported);
  MPI_Gather(times, kReported, MPI_DOUBLE, all.data(), kReported, MPI_DOUBLE, 0, MPI_COMM_WORLD);

  return collectively(rank, [&] {
    if (rank != 0) return;
    const MomentImage image =
        momentImageOf(std::move(whole), grid, camera, o.settings, valueMin, valueMax);
    const auto tWrite = Clock::now();
    writeMomentImage(image, o.out);
    const double writeMs = msSince(tWrite);
    int64_t hit = 0;
    for (uint8_t c : image.counts) hit += c > 0;
    if (o.json) {
      nlohmann::json perRank = nlohmann::json::array();
      for (int r = 0; r < ranks; ++r)
        perRank.push_back({{"rank", r},
                           {"slices", {shareOf(nz, r, ranks).begin, shareOf(nz, r, ranks).end}},
                           {"slabs", int(all[size_t(r) * kReported + 2])},
                           {"slices_read", int(all[size_t(r) * kReported + 4])},
                           {"read_ms", all[size_t(r) * kReported]},
                           {"march_ms", all[size_t(r) * kReported + 1]},
                           {"count_ms", all[size_t(r) * kReported + 3]}});
      const nlohmann::json d = {{"command", "moments-mpi generate"},
                                {"input", src.name},
                                {"ranks", ranks},
                                {"threads_per_rank", threads},
                                {"file", o.out},
                                {"size", {image.width, image.height}},
                                {"order", image.order},
                                {"pixels_hit", hit},
                                {"moments_stored", image.moments.size()},
                                {"memory_limit_bytes", limit},
                                {"largest_slab_bytes_rank0", largestSlab},
                                {"value_range", {valueMin, valueMax}},
                                {"times_ms",
                                 {{"range", rangeMs},
                                  {"reduce", reduceMs},
                                  {"count", countWallMs},
                                  {"gather", gatherMs},
                                  {"write", writeMs}}},
                                {"per_rank", perRank},
                                {"bytes", double(std::filesystem::file_size(o.out))}};
      std::printf("%s\n", d.dump(2).c_str());
    } else {
      std::printf(
          "%s: %dx%d pixels, order %d, %lld pixels hit, %.1f moments per hit pixel, %d "
          "ranks of %d threads\n",
          o.out.c_str(), image.width, image.height, image.order, static_cast<long long>(hit),
          hit > 0 ? double(image.moments.size()) / double(hit) : 0.0, ranks, threads);
      for (int r = 0; r < ranks; ++r)
        std::printf("rank %d: %d slab(s), read %.0f ms, march %.0f ms, count %.0f ms\n", r,
                    int(all[size_t(r) * 4 + 2]), all[size_t(r) * 4], all[size_t(r) * 4 + 1],
                    all[size_t(r) * 4 + 3]);
      std::printf("range %.0f ms, reduce %.0f ms, count %.0f ms, gather %.0f ms, write %.0f ms\n",
                  rangeMs, reduceMs, countWallMs, gatherMs, writeMs);
    }
  });
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);

  CLI::App app{"visopt-moments-mpi: moment images (Rapp et al. 2022) generated across MPI ranks"};
  app.option_defaults()->always_capture_default();
  app.require_subcommand(1);
  Options o;
  CLI::App* gen = app.add_subcommand(
      "generate", "March a volume across the ranks and write its moment image (rank 0 writes)");
  CLI::Option* volume = gen->add_option(
      "--volume", o.volume,
      "Volume file read by slabs: raw with a JSON sidecar, MetaImage or NIfTI, uncompressed");
  CLI::Option* scene = gen->add_option(
      "--scene", o.scene, "Built-in scene, builtin:NAME (generated whole on each rank)");
  volume->excludes(scene);
  gen->add_option("--resolution", o.resolution, "Built-in scene resolution (longest axis)");
  gen->add_option("--camera", o.camera,
                  "Orbit AZ,EL,DIST: degrees about +z, degrees above the xy-plane, distance in "
                  "bounding-sphere radii")
      ->default_str("the scene's view, or 0,10,2.6 for a volume file");
  gen->add_option("--size", o.size, "Image size WxH");
  gen->add_option("--moments", o.settings.moments,
                  "Order m: moments 0..m are generated (at most 127)");
  gen->add_option(
      "--error", o.settings.errorThreshold,
      "Per-pixel moment count: the fewest within this rRMSE of all m + 1 (0 keeps all)");
  gen->add_option("--margin", o.settings.boundsMargin,
                  "Epsilon of the per-pixel bounds [min - eps, max + eps] (density units)");
  gen->add_option("--step", o.settings.stepVoxels,
                  "Ray-march step in units of the smallest voxel spacing");
  gen->add_option("--memory-limit", o.memoryLimit,
                  "Bytes of volume data a rank holds at once (e.g. 64M): its slices are read in "
                  "slabs that fit, each with its halo")
      ->default_str("none: a rank reads its share of the slices at once");
  gen->add_option("--threads", o.threads,
                  "CPU threads per rank (oneTBB); 0: the machine's cores shared among the ranks "
                  "on it");
  gen->add_option("--out", o.out, "Output .vmi file (written by rank 0)")->required();
  gen->add_flag("--json", o.json, "Print per-stage and per-rank times as JSON (rank 0)");

  int code = 0;
  try {
    app.parse(argc, argv);
    if (o.volume.empty() && o.scene.empty()) throw CLI::RequiredError("--volume or --scene");
  } catch (const CLI::CallForHelp& e) {
    if (rank == 0) app.exit(e);
    MPI_Finalize();
    return 0;
  } catch (const CLI::ParseError& e) {
    if (rank == 0) app.exit(e);
    MPI_Finalize();
    return visopt::cli::kUsage;
  }
  // Ranks on one machine share its cores: by default each runs cores / local ranks threads.
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &local);
  int localRanks = 1;
  MPI_Comm_size(local, &localRanks);
  MPI_Comm_free(&local);
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = o.threads > 0 ? o.threads : std::max(1, cores / localRanks);
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    code = run(rank, ranks, o, threads);
  }
  MPI_Finalize();
  return code;
}
