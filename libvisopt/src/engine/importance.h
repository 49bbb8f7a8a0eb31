// Building the importance field g(x) in [0, 1] (Himmler & Günther 2026, §III-A) from what a user
// gives: a curve over the data values, a curve file, or a volume on the same grid.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "visopt/field.h"
#include "visopt/volume.h"

namespace visopt {

// g(x) = curve(s(x)), the curve piecewise linear over data values, constant beyond its ends.
// Refuses (BadInput naming `origin`) an empty curve, NaN, or g outside [0, 1].
Field3D importanceFromCurve(const Volume& volume, const std::vector<glm::dvec2>& points,
                            const std::string& origin, Precision precision, MemoryLedger* ledger);
// The same over normalised values t in [0, 1] (the built-in scenes' curves).
Field3D importanceFromNormalizedCurve(const Volume& volume, const std::vector<glm::vec2>& points,
                                      Precision precision, MemoryLedger* ledger);
// A smooth ball: g = 1 within radius / 2 of `centre`, 1 - smoothstep over [radius / 2, radius],
// 0 beyond (world units).
Field3D importanceFromHotspot(const Volume& volume, glm::vec3 centre, float radius,
                              Precision precision, MemoryLedger* ledger);
// True for .json files.
bool isCurveFile(const std::string& path);
// {"points": [[value, g], ...]} or a visopt transfer-function JSON (its opacity read as g).
std::vector<glm::dvec2> readImportanceCurve(const std::string& path);
// A volume file on the volume's grid (same dims) with values in [0, 1].
Field3D importanceFromVolumeFile(const Volume& volume, const std::string& path, Precision precision,
                                 MemoryLedger* ledger);

}  // namespace visopt
