// Building a context surface's base SDF phi0 on the volume grid from its spec.
#pragma once

#include "visopt/engine.h"
#include "visopt/field.h"

namespace visopt {

class MemoryLedger;

Field3D buildContextSurface(const ContextSurfaceSpec& spec, const Volume& volume,
                            const LevelSetSettings& levelSet, Precision precision,
                            MemoryLedger* ledger, const ProgressCallback& progress);

}  // namespace visopt
