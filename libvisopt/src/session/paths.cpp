#include "session/paths.h"

#include <filesystem>

namespace visopt::session {

namespace fs = std::filesystem;

std::string absolutePath(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(fs::path(path), ec);
  if (ec) p = fs::path(path);
  return p.lexically_normal().string();
}

std::string sessionFolder(const std::string& sessionPath) {
  return fs::path(absolutePath(sessionPath)).parent_path().string();
}

std::string relativeTo(const std::string& path, const std::string& folder) {
  const fs::path rel = fs::path(absolutePath(path)).lexically_relative(absolutePath(folder));
  return rel.empty() ? std::string() : rel.generic_string();
}

}  // namespace visopt::session
