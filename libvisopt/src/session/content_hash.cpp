#include "session/content_hash.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "session/sha256.h"
#include "visopt/error.h"

namespace visopt::session {

namespace fs = std::filesystem;

namespace {

struct FileEntry {
  std::string name;  // path for a single file, file name inside a folder
  fs::path path;
  uint64_t size = 0;
  int64_t mtime = 0;
};

std::vector<FileEntry> listEntries(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throwBadInput(path, "file not found");
  std::vector<FileEntry> entries;
  auto describe = [&](const fs::path& p, std::string name) {
    FileEntry e;
    e.name = std::move(name);
    e.path = p;
    e.size = fs::file_size(p, ec);
    if (ec) throwBadInput(p.string(), "cannot read its size (" + ec.message() + ")");
    e.mtime = static_cast<int64_t>(fs::last_write_time(p, ec).time_since_epoch().count());
    entries.push_back(std::move(e));
  };
  if (fs::is_directory(st)) {
    for (const auto& entry : fs::directory_iterator(path, ec))
      if (entry.is_regular_file(ec)) describe(entry.path(), entry.path().filename().string());
    if (ec) throwBadInput(path, "cannot list the folder (" + ec.message() + ")");
    std::sort(entries.begin(), entries.end(),
              [](const FileEntry& a, const FileEntry& b) { return a.name < b.name; });
  } else {
    describe(path, {});
  }
  return entries;
}

constexpr size_t kChunkBytes = size_t(1) << 20;
constexpr uint64_t kReportEveryBytes = uint64_t(16) << 20;

// Streams `path` into `h`; `onChunk(bytes)` after every chunk.
template <class OnChunk>
void hashFile(Sha256& h, const fs::path& path, OnChunk&& onChunk) {
  // Only regular files: a session must not make visopt read a device (/dev/zero never ends)
  // or block on a FIFO.
  std::error_code ec;
  if (!fs::is_regular_file(fs::status(path, ec)))
    throwBadInput(path.string(), "is not a regular file; only data files are checked");
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throwBadInput(path.string(), std::string("cannot open: ") + std::strerror(errno));
  std::vector<char> buffer(kChunkBytes);
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), f.get())) > 0) {
    h.update(buffer.data(), n);
    onChunk(n);
  }
  if (std::ferror(f.get())) throwBadInput(path.string(), "read error");
}

std::string signatureOf(const std::vector<FileEntry>& entries) {
  std::string s;
  for (const auto& e : entries)
    s += e.name + '\0' + std::to_string(e.size) + ':' + std::to_string(e.mtime) + '\n';
  return s;
}

struct CacheEntry {
  std::string signature;
  ContentHash hash;
};

std::mutex cacheMutex;
std::map<std::string, CacheEntry> cache;

struct Listing {
  std::vector<FileEntry> entries;
  bool folder = false;
  std::string key, signature;
  uint64_t bytes = 0;
};

Listing list(const std::string& path) {
  Listing l;
  std::error_code ec;
  l.key = fs::absolute(path, ec).lexically_normal().string();
  l.entries = listEntries(path);
  l.folder = l.entries.empty() || !l.entries.front().name.empty();
  l.signature = std::string(l.folder ? "dir\n" : "file\n") + signatureOf(l.entries);
  for (const auto& e : l.entries) l.bytes += e.size;
  return l;
}

std::optional<ContentHash> lookUp(const Listing& l) {
  std::lock_guard<std::mutex> lock(cacheMutex);
  auto it = cache.find(l.key);
  if (it != cache.end() && it->second.signature == l.signature) return it->second.hash;
  return std::nullopt;
}

}  // namespace

uint64_t contentBytes(const std::string& path) {
  return list(path).bytes;
}

std::optional<ContentHash> cachedContentHash(const std::string& path) {
  return lookUp(list(path));
}

ContentHash hashContent(const std::string& path, const ProgressCallback& progress) {
  const Listing listing = list(path);
  if (auto hit = lookUp(listing)) return *hit;
  const std::vector<FileEntry>& entries = listing.entries;
  const bool folder = listing.folder;
  uint64_t done = 0, reported = 0;
  auto onChunk = [&](size_t n) {
    done += n;
    if (!progress || done - reported < kReportEveryBytes) return;
    reported = done;
    const float fraction = float(double(done) / double(std::max<uint64_t>(listing.bytes, done)));
    if (!progress(fraction, "checking " + path))
      throw Error(ErrorKind::Cancelled, path + ": checking its content was cancelled");
  };
  Sha256 h;
  ContentHash out;
  for (const auto& e : entries) {
    if (folder) {
      h.update(e.name.data(), e.name.size() + 1);  // with its NUL
      uint8_t size[8];
      for (int i = 0; i < 8; ++i) size[i] = uint8_t(e.size >> (8 * i));
      h.update(size, sizeof(size));
    }
    hashFile(h, e.path, onChunk);
    out.bytes += e.size;
  }
  out.sha256 = h.hexDigest();
  std::lock_guard<std::mutex> lock(cacheMutex);
  cache[listing.key] = {listing.signature, out};
  return out;
}

}  // namespace visopt::session
