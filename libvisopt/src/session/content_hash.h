// Content hashes of data files and DICOM folders, streamed (a 100 MB file reads in well under a
// second) and cached per (path, size, modification time) for the life of the process.
#pragma once

#include <cstdint>
#include <string>

namespace visopt::session {

struct ContentHash {
  std::string sha256;  // lowercase hex
  uint64_t bytes = 0;
};

// A regular file: SHA-256 of its bytes. A folder: of its regular files (not recursive) in name
// order, each contributing its name, a NUL, its size as 8 little-endian bytes, and its bytes.
// Throws BadInput "PATH: ..." when the path does not exist or cannot be read.
ContentHash hashContent(const std::string& path);

}  // namespace visopt::session
