// The file inside a context surface's source ("mesh:FILE", "vdb:FILE"; "iso:..." has none).
#pragma once

#include <optional>
#include <string>

namespace visopt::session {

std::optional<std::string> surfaceFile(const std::string& source);
// The source with its file replaced (the kind prefix kept).
std::string withSurfaceFile(const std::string& source, const std::string& file);

}  // namespace visopt::session
