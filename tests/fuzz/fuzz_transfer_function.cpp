// libFuzzer target for transfer-function JSON (visopt's format and ParaView's exported colour
// maps): what fromJson accepts must bake, and its own JSON must load again.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fuzz_input_file.h"
#include "visopt/error.h"
#include "visopt/transfer_function.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  visopt::TransferFunction tf;
  try {
    tf = visopt::TransferFunction::fromJson(text, "fuzz.json");
  } catch (const visopt::Error& e) {
    visopt::fuzz::expectBadInput(e);
    return 0;
  }
  (void)tf.bake(-1000.0, 3000.0, 1.f, 256);
  // Written by visopt, read by visopt: refusing its own output would be a bug.
  (void)visopt::TransferFunction::fromJson(tf.toJson(), "fuzz.json (written back)");
  return 0;
}
