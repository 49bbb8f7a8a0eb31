// What the UI thread may read of the scene while the engine works on its own thread: immutable
// copies taken when the data, the transfer function or the surfaces change. Tools (picking,
// mask painting, the histogram) read these, never the Engine.
#pragma once

#include <memory>
#include <vector>

#include <visopt/camera.h>
#include <visopt/context_surface.h>
#include <visopt/field.h>
#include <visopt/transfer_function.h>
#include <visopt/volume.h>

namespace visopt::ws {

struct SceneSnapshot {
  std::shared_ptr<const Volume> volume;  // scalars (normalised) and grid
  TransferFunction transferFunction;
  // Base SDFs phi0 of the context surfaces, on the volume grid, with their specs.
  std::vector<std::shared_ptr<const Field3D>> surfaceBases;
  std::vector<ContextSurfaceSpec> surfaces;

  const GridSpec* grid() const { return volume ? &volume->grid() : nullptr; }
};

// A host copy of a field (same name, grid and precision; not in any ledger).
Field3D cloneField(const Field3D& field);

}  // namespace visopt::ws
