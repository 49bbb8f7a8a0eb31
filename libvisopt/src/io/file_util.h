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
// The same, refusing a file larger than maxBytes ("PATH: is larger than N MiB, too large for
// KIND"): for text inputs (transfer functions, sessions, curves) that are read whole.
uint64_t checkedFileSize(const std::string& path, uint64_t maxBytes, std::string_view kind);
// Text inputs are read whole: this bounds what a wrong path (a volume given as a transfer
// function) can make visopt read.
inline constexpr uint64_t kMaxTextInputBytes = uint64_t(64) << 20;

// Reads `count` scalars of `type` starting at byte `offset` of `path`, swapping bytes when the
// file's byte order differs from the host's. Throws BadInput "truncated: ..." when the file is
// shorter than offset + count * size.
ScalarData readPayload(const std::string& path, uint64_t offset, ScalarType type, size_t count,
                       bool bigEndian);
// Same for compressed data (zlib or gzip stream starting at `offset`): throws BadInput when the
// stream is corrupt (its checksum included), ends early, or inflates to fewer or more bytes than
// needed, and before allocating when `count` exceeds what the compressed bytes can hold.
ScalarData readCompressedPayload(const std::string& path, uint64_t offset, ScalarType type,
                                 size_t count, bool bigEndian);
// Bytes a whole zlib/gzip file inflates to, streamed (nothing is kept), checksum checked;
// BadInput when it is corrupt or ends early.
uint64_t inflatedSize(const std::string& path);
// Deflate's largest possible expansion (a long run of one byte): ~1032 to 1.
inline constexpr uint64_t kMaxDeflateRatio = 1032;

bool hostIsBigEndian();
void swapBytesInPlace(void* data, size_t count, size_t elementSize);

// Atomic write: makeTemporarySibling("dir/a.nii.gz", ".nii.gz") creates and returns an empty
// "dir/a.nii.gz.tmp-XXXXXX.nii.gz" (keeping `suffix` so writers that look at the extension
// behave); commitTemporary renames it over `path`; discardTemporary removes it.
std::string makeTemporarySibling(const std::string& path, const std::string& suffix);
// Throws Error(Usage) when `path` names a folder, a device, a pipe or a socket (what
// makeTemporarySibling refuses to replace), so that a caller can refuse before its work.
void checkOutputTarget(const std::string& path);
void commitTemporary(const std::string& temporary, const std::string& path);
void discardTemporary(const std::string& temporary) noexcept;

// Temporaries left by a writer that was killed mid-write: every writer holds an exclusive flock
// on its temporary until it commits or discards it, so one whose lock can be taken (and that is
// older than a few seconds, so not one being created right now) has no owner and is removed.
// makeTemporarySibling and saveSession call this for their target before they write, so an
// interrupted save leaves nothing behind past the next save to the same path.
// `prefix` is the start of the temporaries' names in `dir` (e.g. "out.png.tmp-").
void removeStaleTemporaries(const std::string& dir, const std::string& prefix) noexcept;

}  // namespace visopt::io
