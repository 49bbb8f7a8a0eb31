#include "io/file_util.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "visopt/error.h"

namespace visopt::io {

namespace fs = std::filesystem;

bool endsWithNoCase(std::string_view text, std::string_view suffix) {
  if (suffix.size() > text.size()) return false;
  return std::equal(suffix.begin(), suffix.end(), text.end() - std::ptrdiff_t(suffix.size()),
                    [](char a, char b) {
                      return std::tolower(static_cast<unsigned char>(a)) ==
                             std::tolower(static_cast<unsigned char>(b));
                    });
}

std::string fileName(const std::string& path) {
  fs::path p(path);
  if (!p.has_filename()) p = p.parent_path();
  return p.filename().string();
}

std::string parentDir(const std::string& path) {
  fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

std::string siblingPath(const std::string& headerPath, const std::string& name) {
  fs::path p(name);
  if (p.is_absolute()) return name;
  return (fs::path(parentDir(headerPath)) / p).string();
}

uint64_t checkedFileSize(const std::string& path) {
  std::error_code ec;
  fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throwBadInput(path, "file not found");
  if (fs::is_directory(status)) throwBadInput(path, "is a folder, not a file");
  // A device or a FIFO would be read without end (/dev/zero) or block (a pipe nobody writes).
  if (!fs::is_regular_file(status))
    throwBadInput(path, "is a device, pipe or socket, not a regular file");
  uint64_t size = fs::file_size(path, ec);
  if (ec) throwBadInput(path, "cannot read file size (" + ec.message() + ")");
  if (size == 0) throwBadInput(path, "file is empty");
  return size;
}

uint64_t checkedFileSize(const std::string& path, uint64_t maxBytes, std::string_view kind) {
  const uint64_t size = checkedFileSize(path);
  if (size > maxBytes) {
    char limit[64];
    std::snprintf(limit, sizeof limit, "%.0f MiB", double(maxBytes) / double(1 << 20));
    throwBadInput(path,
                  "is larger than " + std::string(limit) + ", too large for " + std::string(kind));
  }
  return size;
}

bool hostIsBigEndian() {
  return std::endian::native == std::endian::big;
}

void swapBytesInPlace(void* data, size_t count, size_t elementSize) {
  if (elementSize <= 1) return;
  auto* bytes = static_cast<unsigned char*>(data);
  for (size_t i = 0; i < count; ++i)
    std::reverse(bytes + i * elementSize, bytes + (i + 1) * elementSize);
}

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

FilePtr openAt(const std::string& path, uint64_t offset) {
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) throwBadInput(path, std::string("cannot open: ") + std::strerror(errno));
  if (offset > uint64_t(std::numeric_limits<long>::max()) ||
      std::fseek(file.get(), static_cast<long>(offset), SEEK_SET) != 0)
    throwBadInput(path, "cannot seek to data offset " + std::to_string(offset));
  return file;
}

std::string sizeText(uint64_t bytes) {
  return std::to_string(bytes) + " bytes";
}

ScalarData makeScalarData(std::shared_ptr<unsigned char[]> buffer, ScalarType type, size_t count) {
  ScalarData out;
  out.type = type;
  out.count = count;
  out.data = buffer.get();
  out.owner = std::shared_ptr<const void>(buffer, buffer.get());
  return out;
}

}  // namespace

ScalarData readPayload(const std::string& path, uint64_t offset, ScalarType type, size_t count,
                       bool bigEndian) {
  const uint64_t fileSize = checkedFileSize(path);
  const size_t elementSize = scalarTypeSize(type);
  const uint64_t need = uint64_t(count) * elementSize;  // caller checked overflow via checkHeader
  if (offset > fileSize || fileSize - offset < need)
    throwBadInput(path, "truncated: header describes " + sizeText(need) + " of data after offset " +
                            std::to_string(offset) + ", file has only " +
                            sizeText(offset > fileSize ? 0 : fileSize - offset));
  auto buffer = std::make_shared_for_overwrite<unsigned char[]>(std::max<size_t>(need, 1));
  FilePtr file = openAt(path, offset);
  if (need > 0 && std::fread(buffer.get(), 1, need, file.get()) != need)
    throwBadInput(path, "truncated: could not read " + sizeText(need) + " of data");
  if (bigEndian != hostIsBigEndian()) swapBytesInPlace(buffer.get(), count, elementSize);
  return makeScalarData(std::move(buffer), type, count);
}

namespace {

// Inflates a zlib or gzip stream from `file` into `out` (up to `want` bytes; more output goes to
// a scratch buffer and is only counted), to the stream's end: the gzip trailer's CRC-32 and
// length, and zlib's Adler-32, are checked there, so a corrupt stream or a missing tail is
// refused rather than taken as good. Returns the total bytes the stream inflates to.
uint64_t inflateStream(const std::string& path, std::FILE* file, unsigned char* out, size_t want) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK)  // 15 + 32: accept zlib or gzip headers
    throwBadInput(path, "cannot initialise zlib");
  std::vector<unsigned char> in(1 << 16), scratch(1 << 16);
  uint64_t produced = 0;
  int rc = Z_OK;
  bool eof = false;
  while (rc != Z_STREAM_END) {
    if (zs.avail_in == 0 && !eof) {
      const size_t got = std::fread(in.data(), 1, in.size(), file);
      eof = got == 0;
      zs.next_in = in.data();
      zs.avail_in = static_cast<uInt>(got);
    }
    if (zs.avail_in == 0 && eof) break;
    const bool intoOut = produced < want;
    const size_t chunk =
        intoOut ? std::min<size_t>(want - size_t(produced), size_t(1) << 30) : scratch.size();
    zs.next_out = intoOut ? out + produced : scratch.data();
    zs.avail_out = static_cast<uInt>(chunk);
    rc = inflate(&zs, Z_NO_FLUSH);
    produced += chunk - zs.avail_out;
    if (rc == Z_NEED_DICT || rc == Z_DATA_ERROR || rc == Z_MEM_ERROR) {
      const std::string message = zs.msg ? zs.msg : "data error";
      inflateEnd(&zs);
      throwBadInput(path, "corrupt compressed data (zlib: " + message + ")");
    }
    if (rc == Z_BUF_ERROR && zs.avail_in == 0 && eof) break;
  }
  inflateEnd(&zs);
  if (rc != Z_STREAM_END)
    throwBadInput(path, "truncated: the compressed data ends before its stream does (" +
                            sizeText(produced) + " inflated)");
  return produced;
}

}  // namespace

ScalarData readCompressedPayload(const std::string& path, uint64_t offset, ScalarType type,
                                 size_t count, bool bigEndian) {
  const uint64_t fileSize = checkedFileSize(path);
  if (offset >= fileSize) throwBadInput(path, "truncated: no compressed data after the header");
  const size_t elementSize = scalarTypeSize(type);
  const size_t need = count * elementSize;
  // Deflate inflates at most ~1032 to 1: a header that promises more than the compressed bytes
  // can hold is refused before its buffer is allocated.
  const uint64_t compressed = fileSize - offset;
  if (need / kMaxDeflateRatio > compressed)
    throwBadInput(path, "truncated: header describes " + sizeText(need) + ", " +
                            sizeText(compressed) + " of compressed data inflate to at most " +
                            sizeText(compressed * kMaxDeflateRatio));
  auto buffer = std::make_shared_for_overwrite<unsigned char[]>(std::max<size_t>(need, 1));
  FilePtr file = openAt(path, offset);
  const uint64_t produced = inflateStream(path, file.get(), buffer.get(), need);
  if (produced < need)
    throwBadInput(path, "truncated: compressed data inflates to " + sizeText(produced) +
                            ", header describes " + sizeText(need));
  if (produced > need)
    throwBadInput(path, "compressed data inflates to " + sizeText(produced) + ", more than the " +
                            sizeText(need) + " the header describes (wrong dimensions or type?)");
  if (bigEndian != hostIsBigEndian()) swapBytesInPlace(buffer.get(), count, elementSize);
  return makeScalarData(std::move(buffer), type, count);
}

uint64_t inflatedSize(const std::string& path) {
  checkedFileSize(path);
  FilePtr file = openAt(path, 0);
  return inflateStream(path, file.get(), nullptr, 0);
}

void checkOutputTarget(const std::string& path) {
  // The temporary is renamed over the target: over a device that replaced the device itself
  // (as root, --out /dev/full became a PNG). Only regular files, links and new paths are written.
  std::error_code ec;
  const fs::file_status target = fs::symlink_status(path, ec);
  if (!ec && fs::exists(target)) {
    if (fs::is_directory(target))
      throw Error(ErrorKind::Usage, path + ": is a folder; give a file name to write");
    if (!fs::is_regular_file(target) && !fs::is_symlink(target))
      throw Error(ErrorKind::Usage,
                  path + ": is a device, pipe or socket; visopt writes only regular files");
  }
}

namespace {

// The open, flock'ed descriptor of each temporary this process is writing (removeStaleTemporaries).
std::mutex heldMutex;
std::map<std::string, int>& heldTemporaries() {
  static std::map<std::string, int> held;
  return held;
}

void release(const std::string& temporary) noexcept {
  std::lock_guard lock(heldMutex);
  auto& held = heldTemporaries();
  auto it = held.find(temporary);
  if (it == held.end()) return;
  ::close(it->second);
  held.erase(it);
}

}  // namespace

void removeStaleTemporaries(const std::string& dir, const std::string& prefix) noexcept {
  std::error_code ec;
  fs::directory_iterator it(dir.empty() ? "." : dir, ec);
  if (ec) return;
  const auto now = fs::file_time_type::clock::now();
  for (const fs::directory_entry& entry : it) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0 || !entry.is_regular_file(ec)) continue;
    const auto written = entry.last_write_time(ec);
    if (ec || now - written < std::chrono::seconds(5)) continue;  // maybe being created now
    const int fd = ::open(entry.path().c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) ::unlink(entry.path().c_str());  // no owner left
    ::close(fd);
  }
}

std::string makeTemporarySibling(const std::string& path, const std::string& suffix) {
  checkOutputTarget(path);
  removeStaleTemporaries(parentDir(path), fileName(path) + ".tmp-");
  std::string pattern = path + ".tmp-XXXXXX" + suffix;
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  int fd = mkstemps(name.data(), static_cast<int>(suffix.size()));
  if (fd < 0)
    throw Error(ErrorKind::Failure,
                path + ": cannot create a temporary file next to it: " + std::strerror(errno));
  // mkstemp creates rw-------; an output file gets the usual rw-r--r-- less the umask.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd, 0666 & ~mask);
  // Held until commit or discard: the lock tells removeStaleTemporaries that it has an owner.
  ::flock(fd, LOCK_EX);
  std::lock_guard lock(heldMutex);
  heldTemporaries()[std::string(name.data())] = fd;
  return std::string(name.data());
}

void commitTemporary(const std::string& temporary, const std::string& path) {
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    int err = errno;
    discardTemporary(temporary);
    throw Error(ErrorKind::Failure,
                path + ": cannot move the written file into place: " + std::strerror(err));
  }
  release(temporary);
}

void discardTemporary(const std::string& temporary) noexcept {
  std::remove(temporary.c_str());
  release(temporary);
}

}  // namespace visopt::io
