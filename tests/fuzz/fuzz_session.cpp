// libFuzzer target for the session loader and its migrations (any version up to the current
// one): what sessionFromJson accepts must be written back and load again. Nothing here opens
// the data a session references.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input_file.h"
#include "visopt/error.h"
#include "visopt/session.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  visopt::Session session;
  try {
    session = visopt::sessionFromJson(text, "fuzz.visopt-session");
  } catch (const visopt::Error& e) {
    visopt::fuzz::expectBadInput(e);
    return 0;
  }
  const std::string written = visopt::sessionToJson(session, "/tmp/fuzz.visopt-session");
  (void)visopt::sessionFromJson(written, "fuzz.visopt-session (written back)");
  return 0;
}
