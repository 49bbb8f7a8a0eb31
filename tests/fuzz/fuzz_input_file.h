// Shared by the libFuzzer targets: the readers under test take paths, so each input is written
// to a file in a private folder (in /dev/shm when it exists: no disk traffic) and read from
// there. Also the rule every target applies to what the library throws: visopt::Error is the
// answer a bad file deserves; anything else escaping (std::out_of_range, std::bad_alloc, ...)
// is left uncaught so libFuzzer reports it as a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <tbb/global_control.h>

#include "visopt/error.h"

namespace visopt::fuzz {

// One thread per fuzzing process: targets run side by side, one per core, and on inputs of a
// few hundred voxels oneTBB's hand-offs between threads cost more than the work.
inline const tbb::global_control oneThreadPerProcess(tbb::global_control::max_allowed_parallelism,
                                                     1);

// A folder private to this process, created once, removed at exit.
inline const std::string& scratchDir() {
  static const std::string dir = [] {
    namespace fs = std::filesystem;
    const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    const fs::path d = base / ("visopt-fuzz-" + std::to_string(getpid()));
    fs::create_directories(d);
    static const std::string keep = d.string();
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(keep, ec);
    });
    return d.string();
  }();
  return dir;
}

// True when VISOPT_FUZZ_DOWNSTREAM=1: accepted inputs also go through what follows the reader
// (a render, an SDF conversion). That costs most of an execution, so the fuzzing runs read only
// and run_fuzzers.sh then replays every corpus input with this on.
inline bool downstreamChecks() {
  static const bool on = [] {
    const char* v = std::getenv("VISOPT_FUZZ_DOWNSTREAM");
    return v && std::string(v) == "1";
  }();
  return on;
}

// The rule for what a target catches: BadInput is the answer a broken file deserves; any other
// visopt::Error kind (Usage, Failure, ...) is a finding, reported with its message.
inline void expectBadInput(const Error& e) {
  if (e.kind() == ErrorKind::BadInput) return;
  std::fprintf(stderr, "visopt fuzz: an error of kind %d escaped: %s\n", int(e.kind()), e.what());
  std::abort();
}

// Writes `size` bytes to scratchDir()/name and returns the path.
inline std::string writeInput(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratchDir() + "/" + name;
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

}  // namespace visopt::fuzz
