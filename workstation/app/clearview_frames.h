// Helpers of the ClearView frames (the Hotspot tool): comparing hotspot settings and turning the
// library's linear image into what the viewport paints, fast enough for a frame per cursor move.
#pragma once

#include <QImage>

#include <visopt/clearview.h>
#include <visopt/image.h>

namespace visopt::ws {

// Whether `a` and `b` render the same hotspot apart from the view: every member but width,
// height and focusPixel (the members a session stores).
bool sameHotspotSettings(const ClearViewSettings& a, const ClearViewSettings& b);

// `image` as 8-bit sRGB (Image::writeSrgb8) straight into the QImage the viewport paints.
QImage toDisplayImage(const Image& image);

}  // namespace visopt::ws
