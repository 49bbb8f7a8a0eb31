// Sessions: everything a user set, saved to one JSON file and rebuilt into an Engine.
//
// The format is owned by the library so the CLI and the workstation share it. It follows the
// Inviwo model: a file stores only values that differ from the defaults (plus the format and its
// version), and older versions load through a chain of converters, each raising the version by
// one. Data files are not copied into the session: a DataReference names each by absolute path,
// by path relative to the session file, and by content hash (SHA-256), tried in that order. A
// missing or changed file is reported (SessionLoadReport), never fatal. The world mask, which a
// user may have painted for an hour, is stored inside the file (bit-packed, zstd, base64).
//
// Saving is atomic (temporary sibling, fsync, rename): a crash mid-save leaves the previous file
// intact. Loading a truncated, corrupt, foreign or newer-version file throws
// Error(BadInput, "PATH: problem").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "visopt/bit_mask.h"
#include "visopt/camera.h"
#include "visopt/clearview.h"
#include "visopt/engine.h"
#include "visopt/importance_kind.h"
#include "visopt/level_set.h"
#include "visopt/optimization.h"
#include "visopt/precision.h"
#include "visopt/progress.h"
#include "visopt/render_settings.h"
#include "visopt/transfer_function.h"

namespace visopt {

// The version sessionToJson writes. History (each step has a converter, see session_migrate):
//   1: camera stored as an orbit {"target", "azimuth", "elevation", "distance", "fovY"}
//   2: camera stored as {"eye", "target", "up", "fovY"}
//   3: "tf" renamed "transferFunction", "surfaces" renamed "contextSurfaces"
//   4: "clearView" (the ClearView hotspot's settings) and the importance kind "hotspot"
//   5: "clearView" may list more layers: "deeperContexts" and "moreFoci"
inline constexpr int kSessionFormatVersion = 5;

// ---- data references ----------------------------------------------------------------------

// A data file (or DICOM folder) named three ways. sha256 is lowercase hex of the file's bytes;
// for a folder, of its regular files in name order (each: name, NUL, 8-byte little-endian size,
// contents). `bytes` is the file size (a folder: the sum over its files).
struct DataReference {
  std::string absolutePath, relativePath;  // relativePath: to the session file's folder, '/'
  std::string sha256;
  uint64_t bytes = 0;
  bool empty() const { return absolutePath.empty() && relativePath.empty(); }
  bool operator==(const DataReference&) const = default;
};

// Describes `path` (made absolute) for a session to be saved at `sessionPath` (relativePath stays
// empty when sessionPath is empty). Hashes the content; results are cached per (path, size,
// modification time) for the life of the process. Throws BadInput when `path` is unreadable;
// `progress` hears the hashing, and returning false throws Error(Cancelled).
DataReference makeDataReference(const std::string& path, const std::string& sessionPath,
                                const ProgressCallback& progress = {});
// Recomputes relativePath for a session saved at a new place.
DataReference rebaseDataReference(DataReference ref, const std::string& sessionPath);

enum class DataStatus {
  Ok,          // found at its absolute path, same content
  Moved,       // found through its path relative to the session, same content
  Changed,     // found, but its content hash differs (still used unless the caller refuses)
  Missing,     // found nowhere
  Unreadable,  // found, but reading it failed (message says why)
};
const char* toString(DataStatus status);

// How much of a data file is read to decide that it is the one a session was saved with.
enum class DataCheck {
  Content,  // its SHA-256 (streamed; a file already hashed unchanged by this process is not reread)
  Size,     // its size only, from the file system; the content is checked later (verifySessionData)
};

struct DataResolution {
  DataStatus status = DataStatus::Missing;
  std::string resolvedPath;  // empty when Missing
  // The verdict is final: decided by the content hash, a size that differs, or absence; false
  // when DataCheck::Size found the recorded size and the content is still to be checked.
  bool contentVerified = false;
};
// Absolute path first, then the relative path against the session's folder; a candidate whose
// hash matches wins over one that exists with other content. A candidate whose size differs from
// the recorded `bytes` is Changed without being read. `progress` hears the hashing; returning
// false throws Error(Cancelled).
DataResolution resolveDataReference(const DataReference& ref, const std::string& sessionPath,
                                    DataCheck check = DataCheck::Content,
                                    const ProgressCallback& progress = {});

// ---- the session ---------------------------------------------------------------------------

// The world mask of a session: a bit-packed mask on the volume grid (visopt/bit_mask.h, which
// also declares packMask).
using SessionMask = BitMask;

struct SessionImportance {
  using Kind = ImportanceKind;  // the engine's ImportanceSource::Kind too
  Kind kind = Kind::None;
  std::vector<glm::dvec2> curve;  // Curve: (value, g) in data units
  DataReference volume;           // Volume: the importance file
  glm::vec3 hotspotCentre{0.f};   // Hotspot: Engine::setImportanceHotspot's, world units
  float hotspotRadius = 0.f;
};

struct SessionSurface {
  ContextSurfaceSpec spec;  // as the user gave it ("mesh:/old/place.obj")
  DataReference file;       // mesh:/vdb: sources: the file; empty for iso:
};

struct Session {
  int version = kSessionFormatVersion;  // the version the file was written with
  // Data: a built-in scene or a volume file.
  std::string builtinScene;  // NAME of builtin:NAME; empty: `volume` is used
  int builtinResolution = 128;
  DataReference volume;
  Precision precision = Precision::FP32;
  std::optional<TransferFunction> transferFunction;  // empty: the engine's default for the data
  SessionImportance importance;
  std::vector<SessionSurface> contextSurfaces;
  ExtinctionSettings extinction;
  LevelSetSettings levelSet;
  std::optional<Camera> camera;  // empty: the framing the data source gives
  std::optional<PointLight> light;
  ImportanceLens lens;
  RenderSettings render;  // image size, deviation view, ... (the engine does not hold them)
  bool frozen = false;
  std::optional<SessionMask> worldMask;
  // The ClearView hotspot's settings (the workstation's Hotspot tool; visopt/clearview.h): all of
  // ClearViewSettings but width, height and focusPixel, which belong to the view and are not
  // stored (they read back as the defaults). Empty: none were set, the scene's defaults apply
  // (docs/clearview.md). They are no Engine state: captureSession leaves them empty and
  // applySession does not use them; the caller sets and reads them.
  std::optional<ClearViewSettings> clearView;
};

// Reads the engine's state. `render` is the caller's render settings (the workstation's view).
// Data files are hashed (cached); references are made relative to `sessionPath` (may be empty;
// saveSession rebases them to where the file goes). Throws Usage when the engine has no volume.
Session captureSession(const Engine& engine, const RenderSettings& render = {},
                       const std::string& sessionPath = {});

// One data file a session needs and what became of it.
struct SessionDataReport {
  std::string role;  // "volume", "importance", "context surface 1", ...
  DataReference reference;
  DataStatus status = DataStatus::Missing;
  std::string resolvedPath;
  std::string message;           // Unreadable: why
  bool contentVerified = false;  // see DataResolution; false after a DataCheck::Size check
};

// One line for people: "volume: moved: found at /new/ct.nii.gz through ../data/ct.nii.gz".
std::string describe(const SessionDataReport& report);

struct SessionLoadReport {
  std::vector<SessionDataReport> data;
  // Settings that could not be applied (a surface that failed to build, a mask of other dims,
  // a precision the engine was not constructed with), one line each.
  std::vector<std::string> warnings;
  // False when the data source could not be loaded: the engine was left as it was.
  bool sceneLoaded = false;
  bool allDataFound() const;  // every reference Ok or Moved
};

struct SessionApplyOptions {
  // A file whose content changed is still used (and reported as Changed); false skips it.
  bool useChangedFiles = true;
  // Content: every data file is hashed before it is loaded. Size: files whose size matches are
  // loaded at once and their content is checked afterwards with verifySessionData (what the
  // workstation does, so a session of large data opens without reading it twice first).
  DataCheck check = DataCheck::Content;
};

// Resolves every data reference without touching an engine (what a workstation shows before it
// asks the user to point to moved files). DataCheck::Size reads no file.
std::vector<SessionDataReport> checkSessionData(const Session& session,
                                                const std::string& sessionPath,
                                                DataCheck check = DataCheck::Content,
                                                const ProgressCallback& progress = {});
// Hashes each report that is Ok or Moved without its content verified (a DataCheck::Size check)
// and sets it to Changed when the hash differs from the one recorded; returns how many changed.
// An unreadable file becomes Unreadable. `progress` spans all the bytes to hash; returning false
// throws Error(Cancelled) and leaves the reports not yet checked as they were.
size_t verifySessionData(std::vector<SessionDataReport>& data,
                         const ProgressCallback& progress = {});
// Points the reference of `role` (as in SessionDataReport) at `newPath`, keeping its recorded
// hash, so the next apply finds it (reported Ok or Changed). Throws Usage for an unknown role.
void relocate(Session& session, const std::string& role, const std::string& newPath);

// Rebuilds the session in the engine: data source, transfer function, importance, surfaces,
// settings, camera, light, mask, frozen flag. Missing or changed data is reported, not thrown;
// whatever can be applied is. The engine's precision is its own (a differing one is a warning).
// Throws only Error(Cancelled) when `progress` asks to stop.
SessionLoadReport applySession(Engine& engine, const Session& session,
                               const std::string& sessionPath,
                               const ProgressCallback& progress = {},
                               const SessionApplyOptions& options = {});

// ---- the file --------------------------------------------------------------------------------

// JSON text of the current version; only non-default values. `sessionPath` rebases relative paths.
std::string sessionToJson(const Session& session, const std::string& sessionPath = {});
// Parses any version up to the current one, migrating step by step; `origin` names the source
// in messages. Throws Error(BadInput, "ORIGIN: problem").
Session sessionFromJson(const std::string& json, const std::string& origin);

// Atomic: a temporary sibling is written, fsynced and renamed over `path`. Throws BadInput when
// the folder does not exist, Failure when writing fails (the old file is then untouched).
void saveSession(const Session& session, const std::string& path);
Session loadSession(const std::string& path);

// Test hook: called at the save stages "temporary-open", "mid-write" and "after-write" (before
// the rename). The environment variable VISOPT_SESSION_FAULT=STAGE makes the process exit
// abruptly (_Exit(70)) at that stage, as a crash would.
using SessionSaveHook = void (*)(const char* stage);
void setSessionSaveHook(SessionSaveHook hook);

}  // namespace visopt
