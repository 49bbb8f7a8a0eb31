#include "engine/context_surfaces.h"

#include <cmath>

#include "optimize/level_set.h"
#include "visopt/error.h"
#include "visopt/sdf.h"

namespace visopt {

namespace {

Field3D isoSurface(const std::string& text, const SurfaceSource& source, const Volume& volume,
                   const LevelSetSettings& ls, Precision precision, MemoryLedger* ledger) {
  if (source.isoValue <= volume.valueMin || source.isoValue >= volume.valueMax)
    throw Error(ErrorKind::Usage, "context '" + text +
                                      "': the isovalue must lie inside the data range (" +
                                      std::to_string(volume.valueMin) + " .. " +
                                      std::to_string(volume.valueMax) + ")");
  return sdfFromIsovalue(volume, source.isoValue, source.insideHigh, ls, precision, ledger);
}

}  // namespace

ContextSurfaceSpec defaultContextSurfaceSpec(const std::string& source, const GridSpec& grid) {
  ContextSurfaceSpec spec;
  spec.source = source;
  if (source.rfind("iso:", 0) == 0) {  // malformed sources are refused when built
    spec.filled = false;
    spec.shell = grid.minSpacing();
  }
  return spec;
}

Field3D buildContextSurface(const ContextSurfaceSpec& spec, const Volume& volume,
                            const LevelSetSettings& levelSet, Precision precision,
                            MemoryLedger* ledger, const ProgressCallback& progress) {
  if (!spec.filled && !(spec.shell > 0.f) && spec.shell != 0.f)
    throw Error(ErrorKind::Usage, "a thin shell needs a thickness d >= 0");
  if (!std::isfinite(spec.shell) || spec.shell < 0.f)
    throw Error(ErrorKind::Usage, "a thin shell needs a finite thickness d >= 0");
  const SurfaceSource source = SurfaceSource::parse(spec.source);
  Field3D phi0;
  switch (source.kind) {
    case SurfaceSource::Kind::Iso:
      phi0 = isoSurface(spec.source, source, volume, levelSet, precision, nullptr);
      break;
    case SurfaceSource::Kind::Mesh: {
      MeshSdfOptions o;
      o.filled = spec.filled;
      o.shellThickness = spec.shell;
      o.like = volume.grid();
      // sdfFromMesh already makes the shell when asked.
      Field3D sdf = sdfFromMesh(source.file, o, precision, nullptr, nullptr, progress);
      sdf.rename("surface-base", ledger);
      return sdf;
    }
    case SurfaceSource::Kind::Vdb:
      phi0 = readSdfVdb(source.file, volume.grid(), precision, nullptr);
      break;
  }
  if (!spec.filled) phi0 = thinShell(phi0, spec.shell, precision, nullptr);
  phi0.rename("surface-base", ledger);
  return phi0;
}

}  // namespace visopt
