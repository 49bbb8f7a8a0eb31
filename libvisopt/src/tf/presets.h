// Transfer-function presets: files resources/transfer-functions/NAME.json (found through the
// VISOPT_RESOURCES environment variable, else the build's VISOPT_RESOURCE_DIR), with a
// compiled-in copy of each so the library works without its resources folder.
#pragma once

#include <string>

#include "visopt/transfer_function.h"

namespace visopt::tfpresets {

// The compiled-in copy of preset `name` as stored (the "generic" preset over [0, 1]);
// throws Error(Usage) for an unknown name.
TransferFunction compiledIn(const std::string& name);

// The preset file that preset(name) would read, or "" when none exists.
std::string presetFile(const std::string& name);

}  // namespace visopt::tfpresets
