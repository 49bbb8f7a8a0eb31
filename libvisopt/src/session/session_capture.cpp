// Reading everything a user set out of an Engine into a Session.
#include <algorithm>

#include "session/surface_source.h"
#include "visopt/error.h"
#include "visopt/session.h"

namespace visopt {

Session captureSession(const Engine& engine, const RenderSettings& render,
                       const std::string& sessionPath) {
  if (!engine.hasVolume()) throw Error(ErrorKind::Usage, "no volume loaded: nothing to save");
  Session s;
  const Volume& volume = engine.volume();
  const std::string builtinPrefix = "builtin:";
  if (volume.sourcePath.rfind(builtinPrefix, 0) == 0) {
    s.builtinScene = volume.sourcePath.substr(builtinPrefix.size());
    const glm::ivec3 dims = volume.grid().dims;
    s.builtinResolution = std::max(dims.x, std::max(dims.y, dims.z));
  } else if (volume.sourcePath.empty()) {
    throw Error(ErrorKind::Usage,
                "the volume was not read from a file: write it to a file before saving a session");
  } else {
    s.volume = makeDataReference(volume.sourcePath, sessionPath);
  }
  s.precision = engine.precision();
  s.transferFunction = engine.transferFunction();

  const Engine::ImportanceSource& imp = engine.importanceSource();
  s.importance.kind = imp.kind;  // one enum for both
  if (imp.kind == ImportanceKind::Curve) s.importance.curve = imp.curve;
  if (imp.kind == ImportanceKind::Volume)
    s.importance.volume = makeDataReference(imp.path, sessionPath);
  if (imp.kind == ImportanceKind::Hotspot) {
    s.importance.hotspotCentre = imp.hotspotCentre;
    s.importance.hotspotRadius = imp.hotspotRadius;
  }

  for (const ContextSurfaceSpec& spec : engine.contextSurfaces()) {
    SessionSurface surface{spec, {}};
    if (auto file = session::surfaceFile(spec.source))
      surface.file = makeDataReference(*file, sessionPath);
    s.contextSurfaces.push_back(std::move(surface));
  }

  s.extinction = engine.extinctionSettings();
  s.levelSet = engine.levelSetSettings();
  s.camera = engine.camera();
  s.light = engine.light();
  s.lens = engine.lens();
  s.render = render;
  s.frozen = engine.frozen();
  if (const BitMask* mask = engine.worldMask()) s.worldMask = *mask;
  return s;
}

}  // namespace visopt
