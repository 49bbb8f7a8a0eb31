// Small file helpers shared by the readers and writers: existence and size checks that throw
// BadInput with "PATH: problem", reading a scalar payload at an offset (with byte swapping and
// a truncation check), zlib/gzip inflation, and atomic replacement through a temporary sibling.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "io/volume_source.h"

namespace visopt::io {

bool endsWithNoCase(std::string_view text, std::string_view suffix);
std::string fileName(const std::string& path);   // last path component
std::string parentDir(const std::string& path);  // "." when there is none
// Resolves `name` relative to the folder holding `headerPath` (absolute names are kept).
std::string siblingPath(const std::string& headerPath, const std::string& name);

// Size of a regular, non-empty file; throws BadInput "file not found", "is a folder, not a
// file", "file is empty" otherwise.
uint64_t checkedFileSize(const std::string& path);

// Reads `count` scalars of `type` starting at byte `offset` of `path`, swapping bytes when the
// file's byte order differs from the host's. Throws BadInput "truncated: ..." when the file is
// shorter than offset + count * size.
ScalarData readPayload(const std::string& path, uint64_t offset, ScalarType type, size_t count,
                       bool bigEndian);
// Same for compressed data (zlib or gzip stream starting at `offset`): throws BadInput when the
// stream is corrupt or inflates to fewer bytes than needed.
ScalarData readCompressedPayload(const std::string& path, uint64_t offset, ScalarType type,
                                 size_t count, bool bigEndian);

bool hostIsBigEndian();
void swapBytesInPlace(void* data, size_t count, size_t elementSize);

// Atomic write: makeTemporarySibling("dir/a.nii.gz", ".nii.gz") creates and returns an empty
// "dir/a.nii.gz.tmp-XXXXXX.nii.gz" (keeping `suffix` so writers that look at the extension
// behave); commitTemporary renames it over `path`; discardTemporary removes it.
std::string makeTemporarySibling(const std::string& path, const std::string& suffix);
void commitTemporary(const std::string& temporary, const std::string& path);
void discardTemporary(const std::string& temporary) noexcept;

}  // namespace visopt::io
