#include "scene_snapshot.h"

#include <cstring>

namespace visopt::ws {

Field3D cloneField(const Field3D& field) {
  Field3D copy(field.name(), field.grid(), field.precision());
  if (!field.empty()) std::memcpy(copy.raw(), field.raw(), field.bytes());
  return copy;
}

}  // namespace visopt::ws
