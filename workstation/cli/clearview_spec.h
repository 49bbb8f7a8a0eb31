// `visopt render --clearview SPEC`: the ClearView hotspot render (Krüger, Schneider, Westermann
// 2006; visopt/clearview.h) configured by one comma-separated list of key=value (docs/clearview.md,
// "Command line").
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "visopt/clearview.h"
#include "visopt/engine.h"
#include "visopt/error.h"

namespace visopt::cli {

// Parses SPEC against the loaded scene (`engine`): every key is optional, an empty SPEC keeps
// every default. Keys:
//   context=iso:V | surface:N | importance:G     (default surface:0 when the scene has one)
//   focus=iso:V | surface:N | importance:G | importance   (default importance:0.5 when the
//                                                          scene has an importance)
//   (context= and focus= may repeat, up to kClearViewMaxLayers each: the further context layers
//   lie behind the first, in the order given; each pixel shows the nearest focus layer)
//   volume=0|1  measure=curvature|distance|view-distance
//   shader=, focus-shader=diffuse|cool-warm|skin|bone
//   at=PX:PY  size=MM  weight=W  distance-scale=MM  border=0|1  ambient=A  light=camera|scene
// `imageSize` (the render's --size) becomes the settings' width and height and bounds at=.
// `base` (a session's saved settings, or null) replaces the defaults, layers included; SPEC's
// keys override it. Throws Error(Usage) with one line naming --clearview and the offending
// element.
ClearViewSettings parseClearViewSpec(const Engine& engine, const std::string& spec,
                                     glm::ivec2 imageSize, const ClearViewSettings* base = nullptr);

// A usage error of the library's ClearView checks (checkClearViewSettings, or the Engine's checks
// of the layers against the scene) as this option's: "--clearview: PROBLEM".
Error asClearViewOptionError(const Error& error);

// "iso:-400", "surface:0", "importance:0.5": a layer as SPEC writes it.
std::string describeClearViewLayer(const ClearViewLayer& layer);

}  // namespace visopt::cli
