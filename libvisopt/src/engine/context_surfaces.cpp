#include "engine/context_surfaces.h"

#include <cmath>

#include "optimize/level_set.h"
#include "visopt/error.h"
#include "visopt/sdf.h"

namespace visopt {

namespace {

bool startsWith(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

Field3D isoSurface(const std::string& spec, const Volume& volume, const LevelSetSettings& ls,
                   Precision precision, MemoryLedger* ledger) {
  // iso:VALUE[:inside-high|inside-low]
  std::string rest = spec.substr(4);
  bool insideHigh = true;
  const auto colon = rest.find(':');
  if (colon != std::string::npos) {
    const std::string side = rest.substr(colon + 1);
    if (side == "inside-high")
      insideHigh = true;
    else if (side == "inside-low")
      insideHigh = false;
    else
      throw Error(ErrorKind::Usage, "context '" + spec + "': expected inside-high or inside-low");
    rest = rest.substr(0, colon);
  }
  double value = 0.0;
  try {
    size_t used = 0;
    value = std::stod(rest, &used);
    if (used != rest.size()) throw std::invalid_argument(rest);
  } catch (const std::exception&) {
    throw Error(ErrorKind::Usage, "context '" + spec + "': VALUE must be a number");
  }
  if (!std::isfinite(value) || value <= volume.valueMin || value >= volume.valueMax)
    throw Error(ErrorKind::Usage, "context '" + spec +
                                      "': the isovalue must lie inside the data range (" +
                                      std::to_string(volume.valueMin) + " .. " +
                                      std::to_string(volume.valueMax) + ")");
  return sdfFromIsovalue(volume, value, insideHigh, ls, precision, ledger);
}

}  // namespace

ContextSurfaceSpec defaultContextSurfaceSpec(const std::string& source, const GridSpec& grid) {
  ContextSurfaceSpec spec;
  spec.source = source;
  if (startsWith(source, "iso:")) {
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
  Field3D phi0;
  if (startsWith(spec.source, "iso:")) {
    phi0 = isoSurface(spec.source, volume, levelSet, precision, nullptr);
  } else if (startsWith(spec.source, "mesh:")) {
    MeshSdfOptions o;
    o.filled = spec.filled;
    o.shellThickness = spec.shell;
    o.like = volume.grid();
    // sdfFromMesh already makes the shell when asked.
    Field3D sdf = sdfFromMesh(spec.source.substr(5), o, precision, nullptr, nullptr, progress);
    sdf.rename("surface-base", ledger);
    return sdf;
  } else if (startsWith(spec.source, "vdb:")) {
    phi0 = readSdfVdb(spec.source.substr(4), volume.grid(), precision, nullptr);
  } else {
    throw Error(ErrorKind::Usage, "context '" + spec.source +
                                      "': expected iso:VALUE[:inside-high|inside-low], mesh:FILE "
                                      "or vdb:FILE");
  }
  if (!spec.filled) phi0 = thinShell(phi0, spec.shell, precision, nullptr);
  phi0.rename("surface-base", ledger);
  return phi0;
}

}  // namespace visopt
