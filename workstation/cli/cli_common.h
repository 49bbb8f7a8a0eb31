// Shared pieces of the visopt command-line tool: exit codes, option parsing helpers, and the
// JSON reports (stage timings, memory ledger).
#pragma once

#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "visopt/engine.h"

namespace visopt::cli {

// Exit codes: 0 success, 1 usage error, 2 bad input, 3 any other failure.
enum ExitCode { kOk = 0, kUsage = 1, kBadInput = 2, kFailure = 3 };

// "WxH" -> (W, H); throws Error(Usage).
glm::ivec2 parseSize(const std::string& text);
// Finite numbers separated by `sep`; throws Error(Usage) naming `what`.
std::vector<float> parseFloats(const std::string& text, char sep, const std::string& what);
// "A,B,C" -> three floats; throws Error(Usage) naming `what`.
glm::vec3 parseTriple(const std::string& text, const std::string& what);

// Loads --volume FILE or --scene builtin:NAME into the engine; exactly one must be given.
void loadInput(Engine& engine, const std::string& volume, const std::string& scene,
               int sceneResolution, bool showProgress);
// --tf: a JSON file (visopt or ParaView format) or preset:NAME.
TransferFunction loadTransferFunction(const std::string& spec, const Volume& volume);
// --importance preset:NAME, or, without --importance and --scene, the importance a --tf preset
// is made for (bone for the CT presets): sets it and returns true; false when neither applies.
bool applyPresetImportance(Engine& engine, const std::string& importance, const std::string& scene,
                           const std::string& tf);

nlohmann::json stageTimingsJson();
nlohmann::json ledgerJson(const MemoryLedger& ledger);
std::string humanBytes(size_t bytes);

}  // namespace visopt::cli
