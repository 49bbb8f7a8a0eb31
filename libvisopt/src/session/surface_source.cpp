#include "session/surface_source.h"

namespace visopt::session {

namespace {
bool hasFile(const std::string& source) {
  return source.rfind("mesh:", 0) == 0 || source.rfind("vdb:", 0) == 0;
}
}  // namespace

std::optional<std::string> surfaceFile(const std::string& source) {
  if (!hasFile(source)) return std::nullopt;
  return source.substr(source.find(':') + 1);
}

std::string withSurfaceFile(const std::string& source, const std::string& file) {
  if (!hasFile(source)) return source;
  return source.substr(0, source.find(':') + 1) + file;
}

}  // namespace visopt::session
