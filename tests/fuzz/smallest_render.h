// The cheapest render of a whole volume: 16 x 16 pixels with the smallest light grid. What a
// reader accepts the renderer must work on (issue 13): the volume fuzz targets and the unit test
// that replays their findings ask this of every volume a reader accepted.
#pragma once

#include <utility>

#include "visopt/engine.h"
#include "visopt/image.h"
#include "visopt/render_settings.h"
#include "visopt/volume.h"

namespace visopt::fuzz {

inline Image renderSmallest(Volume volume) {
  constexpr int kPixels = 16;
  Engine engine;
  engine.setVolume(std::move(volume));
  RenderSettings settings;
  settings.width = settings.height = kPixels;
  settings.lightGridSize = kMinLightGridSize;
  engine.setViewportSize(kPixels, kPixels);
  return engine.render(settings);
}

}  // namespace visopt::fuzz
