// Where the importance g(x) in [0, 1] comes from (Himmler & Günther 2026, §III-A): the engine's
// ImportanceSource and a session's SessionImportance share this one enum.
#pragma once

namespace visopt {

enum class ImportanceKind { None, Scene, Curve, Volume };

// "none", "scene", "curve" or "volume": the names the session format uses.
const char* toString(ImportanceKind kind);

}  // namespace visopt
