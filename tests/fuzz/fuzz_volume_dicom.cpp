// libFuzzer target for the DICOM series reader: the input is the one slice of a series folder.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "fuzz_input_file.h"
#include "fuzz_read_and_render.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string folder = [] {
    std::filesystem::create_directories(visopt::fuzz::scratchDir() + "/series");
    return visopt::fuzz::scratchDir() + "/series";
  }();
  visopt::fuzz::writeInput("series/slice.dcm", data, size);
  visopt::fuzz::readAndRender(folder);
  return 0;
}
