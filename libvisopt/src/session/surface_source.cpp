#include "session/surface_source.h"

#include "visopt/context_surface.h"
#include "visopt/error.h"

namespace visopt::session {

namespace {
// The typed source, or nothing for text that is not a source with a file (iso:, or malformed:
// the engine reports that when it builds the surface).
std::optional<SurfaceSource> withFile(const std::string& source) {
  try {
    SurfaceSource s = SurfaceSource::parse(source);
    if (s.hasFile()) return s;
  } catch (const Error&) {
  }
  return std::nullopt;
}
}  // namespace

std::optional<std::string> surfaceFile(const std::string& source) {
  if (auto s = withFile(source)) return s->file;
  return std::nullopt;
}

std::string withSurfaceFile(const std::string& source, const std::string& file) {
  auto s = withFile(source);
  if (!s) return source;
  s->file = file;
  return s->format();
}

}  // namespace visopt::session
