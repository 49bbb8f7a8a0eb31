// libFuzzer target for one volume reader, chosen by the file suffix this unit is compiled with
// (VISOPT_FUZZ_SUFFIX, e.g. ".nii"; tests/fuzz/CMakeLists.txt builds one target per format).
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "fuzz_read_and_render.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  visopt::fuzz::readAndRender(
      visopt::fuzz::writeInput(std::string("input") + VISOPT_FUZZ_SUFFIX, data, size));
  return 0;
}
