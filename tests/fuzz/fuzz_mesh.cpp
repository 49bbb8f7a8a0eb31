// libFuzzer target for one mesh format (VISOPT_FUZZ_SUFFIX: ".off", ".obj", ".ply", ".stl"):
// the mesh is loaded and repaired and, with VISOPT_FUZZ_DOWNSTREAM=1, turned into a shell SDF on
// a fixed 16^3 grid (the conversion a loaded mesh goes through).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input_file.h"
#include "sdf/mesh_loading.h"
#include "visopt/error.h"
#include "visopt/grid.h"
#include "visopt/sdf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path =
      visopt::fuzz::writeInput(std::string("input") + VISOPT_FUZZ_SUFFIX, data, size);
  visopt::MeshSdfOptions options;
  options.filled = false;
  options.shellThickness = 0.05f;
  options.like = visopt::GridSpec{glm::ivec3(16)};
  try {
    visopt::MeshReport report;
    if (visopt::fuzz::downstreamChecks())
      (void)visopt::sdfFromMesh(path, options, visopt::Precision::FP32, nullptr, &report);
    else
      (void)visopt::sdf::loadMesh(path, report, {}, 1.f);
  } catch (const visopt::Error& e) {
    visopt::fuzz::expectBadInput(e);
  }
  return 0;
}
