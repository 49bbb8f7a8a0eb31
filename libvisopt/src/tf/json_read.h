// Small checked readers shared by the transfer-function JSON parsers: every failure is an
// Error(BadInput) "ORIGIN: problem" naming the offending element.
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "visopt/transfer_function.h"

namespace visopt::tfjson {

// A number (integer or floating point) at `what`; anything else is refused.
double readNumber(const nlohmann::json& j, const std::string& origin, const std::string& what);

// ParaView's "Export color map" format: a list of preset objects (or one object) with
// "RGBPoints" [v, r, g, b, ...] and optionally "Points" [v, alpha, midpoint, sharpness, ...].
TransferFunction fromParaView(const nlohmann::json& doc, const std::string& origin);

}  // namespace visopt::tfjson
