#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "clearview_frames.h"

namespace visopt::ws {

bool sameHotspotSettings(const ClearViewSettings& a, const ClearViewSettings& b) {
  return a.context == b.context && a.focus == b.focus && a.deeperContexts == b.deeperContexts &&
         a.moreFoci == b.moreFoci && a.volumeLayer == b.volumeLayer && a.measure == b.measure &&
         a.contextShader == b.contextShader && a.focusShader == b.focusShader && a.size == b.size &&
         a.weight == b.weight && a.distanceScale == b.distanceScale && a.border == b.border &&
         a.ambient == b.ambient && a.headlight == b.headlight && a.contextColor == b.contextColor &&
         a.focusColor == b.focusColor && a.background == b.background;
}

QImage toDisplayImage(const Image& image) {
  QImage out(image.width, image.height, QImage::Format_RGBA8888);
  if (out.isNull() || image.pixels.size() != size_t(image.width) * size_t(image.height)) return {};
  image.writeSrgb8(out.bits(), size_t(out.bytesPerLine()));
  return out;
}

}  // namespace visopt::ws
