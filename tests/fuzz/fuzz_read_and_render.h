// What the volume targets do with a path: read it and, when VISOPT_FUZZ_DOWNSTREAM=1 is set
// (downstreamChecks()), render what the reader accepted (a 16 x 16 image with the smallest light
// grid), because what a reader accepts the renderer must work on (issue 13). Rendering costs most
// of an execution, so the fuzzing runs read only and run_fuzzers.sh then replays every corpus input
// with rendering on. BadInput is the answer a broken file deserves; any other visopt::Error kind,
// like any other exception, escapes as a finding.
#pragma once

#include <string>
#include <utility>

#include "fuzz_input_file.h"
#include "smallest_render.h"
#include "visopt/error.h"
#include "visopt/volume_io.h"

namespace visopt::fuzz {

inline void readAndRender(const std::string& path) {
  try {
    Volume volume = readVolume(path, Precision::FP32);
    if (!downstreamChecks()) return;
    (void)renderSmallest(std::move(volume));
  } catch (const Error& e) {
    expectBadInput(e);
  }
}

}  // namespace visopt::fuzz
