// Path helpers for sessions: absolute names, the session's folder, relative names with '/'.
#pragma once

#include <string>

namespace visopt::session {

// Absolute and lexically normal (symbolic links are kept as the user named them).
std::string absolutePath(const std::string& path);
// The folder holding the session file, absolute.
std::string sessionFolder(const std::string& sessionPath);
// `path` relative to `folder`, with '/' separators; empty when there is no relative form.
std::string relativeTo(const std::string& path, const std::string& folder);

}  // namespace visopt::session
