// Content hashes of data files and DICOM folders, streamed (a 100 MB file reads in well under a
// second) and cached per (path, size, modification time) for the life of the process.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "visopt/progress.h"

namespace visopt::session {

struct ContentHash {
  std::string sha256;  // lowercase hex
  uint64_t bytes = 0;
};

// A regular file: SHA-256 of its bytes. A folder: of its regular files (not recursive) in name
// order, each contributing its name, a NUL, its size as 8 little-endian bytes, and its bytes.
// Throws BadInput "PATH: ..." when the path does not exist or cannot be read. `progress` hears
// the fraction of bytes hashed (about every 16 MiB); returning false throws Error(Cancelled).
ContentHash hashContent(const std::string& path, const ProgressCallback& progress = {});

// The bytes hashContent would read (a folder: the sum over its regular files), from the file
// system's metadata alone. Throws as hashContent does.
uint64_t contentBytes(const std::string& path);

// The hash of `path` when this process has already computed it for the file's current size and
// modification time; nothing is read.
std::optional<ContentHash> cachedContentHash(const std::string& path);

}  // namespace visopt::session
