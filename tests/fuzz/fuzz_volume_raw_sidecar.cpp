// libFuzzer target for the raw reader's JSON sidecar: the input is FILE.raw.json beside a fixed
// FILE.raw of 16 x 16 x 8 int16 values (4 096 bytes).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_input_file.h"
#include "fuzz_read_and_render.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string raw = [] {
    std::vector<uint8_t> bytes(16 * 16 * 8 * 2);
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(i * 7 % 251);
    return visopt::fuzz::writeInput("input.raw", bytes.data(), bytes.size());
  }();
  visopt::fuzz::writeInput("input.raw.json", data, size);
  visopt::fuzz::readAndRender(raw);
  return 0;
}
