#include "visopt/grid.h"

namespace visopt {

Bounds GridSpec::worldBounds() const {
  glm::vec3 hiIndex = glm::vec3(glm::max(dims - 1, glm::ivec3(0)));
  Bounds b{glm::vec3(1e30f), glm::vec3(-1e30f)};
  for (int c = 0; c < 8; ++c) {
    glm::vec3 corner((c & 1) ? hiIndex.x : 0.f, (c & 2) ? hiIndex.y : 0.f,
                     (c & 4) ? hiIndex.z : 0.f);
    glm::vec3 p = indexToWorld(corner);
    b.lo = glm::min(b.lo, p);
    b.hi = glm::max(b.hi, p);
  }
  return b;
}

}  // namespace visopt
