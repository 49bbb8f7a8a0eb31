// Step-by-step migration of session JSON (the Inviwo model): converter k raises a document from
// version k to k + 1, so a file of any older version reaches the current one through the chain.
// A format change adds one converter and bumps kSessionFormatVersion; no converter is ever edited.
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "session/json_read.h"

namespace visopt::session {

using Converter = void (*)(nlohmann::json& doc, const Where& where);

// converters()[k - 1] takes version k to k + 1; there are kSessionFormatVersion - 1 of them.
const std::vector<Converter>& converters();
// Applies the converters from `fromVersion` up and sets doc["version"] to the current one.
void migrate(nlohmann::json& doc, int fromVersion, const Where& where);

}  // namespace visopt::session
