// What a context surface is made of, as a user states it.
#pragma once

#include <string>

#include <glm/glm.hpp>

namespace visopt {

// A context surface (paper 000 §III): opaque geometry held as an SDF on the volume's grid.
struct ContextSurfaceSpec {
  // "iso:VALUE[:inside-high|inside-low]" (an isosurface of the data; inside-high: values above
  // VALUE are inside, the default), "mesh:FILE" (OBJ/PLY/OFF/STL) or "vdb:FILE".
  std::string source;
  bool filled = true;
  float shell = 0.f;  // d of Eq. 26 in world units when !filled: the shell reaches d each side
  glm::vec3 color{0.87f, 0.72f, 0.6f};
  bool visible = true;
};

}  // namespace visopt
