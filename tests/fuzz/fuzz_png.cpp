// libFuzzer target for the PNG reader (images compared by the tests and the CLI).
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "visopt/error.h"
#include "visopt/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)visopt::readPng(visopt::fuzz::writeInput("input.png", data, size));
  } catch (const visopt::Error& e) {
    visopt::fuzz::expectBadInput(e);
  }
  return 0;
}
