#include "scenes/scene_common.h"

#include "visopt/error.h"

namespace visopt::scenes {

void checkResolution(const std::string& scene, int resolution) {
  if (resolution < 2 || resolution > 1024)
    throw Error(ErrorKind::Usage, "scene " + scene + ": resolution " + std::to_string(resolution) +
                                      " is outside [2, 1024]");
}

GridSpec sceneGrid(int resolution) {
  GridSpec g;
  g.dims = glm::ivec3(resolution);
  const float h = kSceneSize / static_cast<float>(resolution - 1);
  g.spacing = glm::vec3(h);
  g.origin = glm::vec3(-kSceneHalf);
  g.direction = glm::mat3(1.f);
  return g;
}

}  // namespace visopt::scenes
