// Data references: a file named by absolute path, by path relative to the session, and by hash.
#include <filesystem>
#include <optional>
#include <vector>

#include "session/content_hash.h"
#include "session/paths.h"
#include "visopt/error.h"
#include "visopt/session.h"

namespace visopt {

namespace fs = std::filesystem;

DataReference makeDataReference(const std::string& path, const std::string& sessionPath,
                                const ProgressCallback& progress) {
  const session::ContentHash hash = session::hashContent(path, progress);
  DataReference ref;
  ref.absolutePath = session::absolutePath(path);
  ref.sha256 = hash.sha256;
  ref.bytes = hash.bytes;
  return rebaseDataReference(std::move(ref), sessionPath);
}

DataReference rebaseDataReference(DataReference ref, const std::string& sessionPath) {
  if (!sessionPath.empty() && !ref.absolutePath.empty())
    ref.relativePath = session::relativeTo(ref.absolutePath, session::sessionFolder(sessionPath));
  return ref;
}

const char* toString(DataStatus status) {
  switch (status) {
    case DataStatus::Ok:
      return "ok";
    case DataStatus::Moved:
      return "moved";
    case DataStatus::Changed:
      return "changed";
    case DataStatus::Missing:
      return "missing";
    case DataStatus::Unreadable:
      return "unreadable";
  }
  return "?";
}

DataResolution resolveDataReference(const DataReference& ref, const std::string& sessionPath,
                                    DataCheck check, const ProgressCallback& progress) {
  struct Candidate {
    std::string path;
    DataStatus whenSame;
  };
  std::vector<Candidate> candidates;
  if (!ref.absolutePath.empty()) candidates.push_back({ref.absolutePath, DataStatus::Ok});
  if (!ref.relativePath.empty() && !sessionPath.empty()) {
    const std::string viaRelative = session::absolutePath(
        (fs::path(session::sessionFolder(sessionPath)) / fs::path(ref.relativePath)).string());
    if (candidates.empty() || candidates.front().path != viaRelative)
      candidates.push_back({viaRelative, DataStatus::Moved});
  }
  std::optional<std::string> changed;
  for (const Candidate& c : candidates) {
    std::error_code ec;
    if (!fs::exists(c.path, ec)) continue;
    try {
      // A size other than the recorded one settles it without reading the file (sessions
      // written before sizes were recorded say 0: those are hashed).
      if (ref.bytes != 0 && session::contentBytes(c.path) != ref.bytes) {
        if (!changed) changed = c.path;
        continue;
      }
      if (ref.sha256.empty()) return {c.whenSame, c.path, true};
      std::optional<session::ContentHash> hash = session::cachedContentHash(c.path);
      if (!hash && check == DataCheck::Size) return {c.whenSame, c.path, false};
      if (!hash) hash = session::hashContent(c.path, progress);
      if (hash->sha256 == ref.sha256) return {c.whenSame, c.path, true};
    } catch (const Error& e) {
      if (e.kind() == ErrorKind::Cancelled) throw;
      return {DataStatus::Unreadable, c.path, true};
    }
    if (!changed) changed = c.path;
  }
  if (changed) return {DataStatus::Changed, *changed, true};
  return {DataStatus::Missing, {}, true};
}

}  // namespace visopt
