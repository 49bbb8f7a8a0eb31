#include "visopt/render_settings.h"

namespace visopt {

const char* toString(RenderMethod method) {
  switch (method) {
    case RenderMethod::Optimized:
      return "ours";
    case RenderMethod::MaxImportanceProjection:
      return "max-importance-projection";
    case RenderMethod::CutAway:
      return "cut-away";
    case RenderMethod::TransparencyModulation:
      return "transparency-modulation";
  }
  return "unknown";
}

}  // namespace visopt
