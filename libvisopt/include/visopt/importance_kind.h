// Where the importance g(x) in [0, 1] comes from (Himmler & Günther 2026, §III-A): the engine's
// ImportanceSource and a session's SessionImportance share this one enum.
#pragma once

namespace visopt {

// Hotspot: a smooth ball about a world point (Engine::setImportanceHotspot).
enum class ImportanceKind { None, Scene, Curve, Volume, Hotspot };

// "none", "scene", "curve", "volume" or "hotspot": the names the session format uses.
const char* toString(ImportanceKind kind);

}  // namespace visopt
