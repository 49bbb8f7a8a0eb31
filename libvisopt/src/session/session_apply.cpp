// Rebuilding a session in an Engine. Data that cannot be found or read is reported, never
// thrown; whatever can be applied is. Without its data source nothing is applied, so the engine
// keeps the scene it had and the caller can relocate the file and apply again.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "session/content_hash.h"
#include "session/paths.h"
#include "session/surface_source.h"
#include "visopt/error.h"
#include "visopt/field.h"
#include "visopt/session.h"

namespace visopt {

namespace {

std::string surfaceRole(size_t index) {
  return "context surface " + std::to_string(index + 1);
}

SessionDataReport check(const std::string& role, const DataReference& ref,
                        const std::string& sessionPath, DataCheck mode,
                        const ProgressCallback& progress) {
  const DataResolution r = resolveDataReference(ref, sessionPath, mode, progress);
  return {role, ref, r.status, r.resolvedPath, {}, r.contentVerified};
}

bool usable(const SessionDataReport& d, const SessionApplyOptions& options) {
  return d.status == DataStatus::Ok || d.status == DataStatus::Moved ||
         (d.status == DataStatus::Changed && options.useChangedFiles);
}

// Runs `f`; an Error other than Cancelled becomes false and its message goes to `message`.
template <class F>
bool attempt(F&& f, std::string& message) {
  try {
    f();
    return true;
  } catch (const Error& e) {
    if (e.kind() == ErrorKind::Cancelled) throw;
    message = e.what();
    return false;
  }
}

class Stages {
 public:
  explicit Stages(const ProgressCallback& progress) : progress_(progress) {}
  void at(float fraction, const std::string& stage) const {
    if (progress_ && !progress_(fraction, stage))
      throw Error(ErrorKind::Cancelled, "loading the session was cancelled");
  }
  // A callback for work spanning [from, to] of the whole.
  ProgressCallback span(float from, float to) const {
    if (!progress_) return {};
    const ProgressCallback& p = progress_;
    return [&p, from, to](float f, const std::string& stage) {
      return p(from + (to - from) * f, stage);
    };
  }

 private:
  const ProgressCallback& progress_;
};

}  // namespace

bool SessionLoadReport::allDataFound() const {
  for (const auto& d : data)
    if (d.status != DataStatus::Ok && d.status != DataStatus::Moved) return false;
  return true;
}

std::vector<SessionDataReport> checkSessionData(const Session& session,
                                                const std::string& sessionPath, DataCheck mode,
                                                const ProgressCallback& progress) {
  std::vector<std::pair<std::string, const DataReference*>> refs;
  if (session.builtinScene.empty()) refs.emplace_back("volume", &session.volume);
  if (session.importance.kind == SessionImportance::Kind::Volume)
    refs.emplace_back("importance", &session.importance.volume);
  for (size_t i = 0; i < session.contextSurfaces.size(); ++i)
    if (!session.contextSurfaces[i].file.empty())
      refs.emplace_back(surfaceRole(i), &session.contextSurfaces[i].file);
  const Stages stages(progress);
  std::vector<SessionDataReport> out;
  for (size_t i = 0; i < refs.size(); ++i) {
    const float from = float(i) / float(refs.size()), to = float(i + 1) / float(refs.size());
    out.push_back(check(refs[i].first, *refs[i].second, sessionPath, mode, stages.span(from, to)));
  }
  return out;
}

size_t verifySessionData(std::vector<SessionDataReport>& data, const ProgressCallback& progress) {
  auto pending = [](const SessionDataReport& d) {
    return !d.contentVerified && !d.reference.sha256.empty() &&
           (d.status == DataStatus::Ok || d.status == DataStatus::Moved);
  };
  uint64_t total = 0, done = 0;
  for (const auto& d : data)
    if (pending(d)) total += d.reference.bytes;
  size_t changed = 0;
  for (auto& d : data) {
    if (!pending(d)) continue;
    const uint64_t bytes = d.reference.bytes;
    const ProgressCallback span =
        !progress ? ProgressCallback{} : ProgressCallback([&](float f, const std::string& stage) {
          return progress(
              float((double(done) + f * double(bytes)) / double(std::max<uint64_t>(total, 1))),
              d.role + ": " + stage);
        });
    try {
      if (session::hashContent(d.resolvedPath, span).sha256 != d.reference.sha256) {
        d.status = DataStatus::Changed;
        ++changed;
      }
    } catch (const Error& e) {
      if (e.kind() == ErrorKind::Cancelled) throw;
      d.status = DataStatus::Unreadable;
      d.message = e.what();
    }
    d.contentVerified = true;
    done += bytes;
  }
  return changed;
}

void relocate(Session& session, const std::string& role, const std::string& newPath) {
  DataReference* ref = nullptr;
  if (role == "volume" && session.builtinScene.empty()) ref = &session.volume;
  if (role == "importance" && session.importance.kind == SessionImportance::Kind::Volume)
    ref = &session.importance.volume;
  for (size_t i = 0; i < session.contextSurfaces.size(); ++i)
    if (role == surfaceRole(i) && !session.contextSurfaces[i].file.empty())
      ref = &session.contextSurfaces[i].file;
  if (!ref) throw Error(ErrorKind::Usage, "the session has no data file \"" + role + "\"");
  ref->absolutePath = session::absolutePath(newPath);
  ref->relativePath.clear();  // recomputed when the session is saved
}

SessionLoadReport applySession(Engine& engine, const Session& session,
                               const std::string& sessionPath, const ProgressCallback& progress,
                               const SessionApplyOptions& options) {
  SessionLoadReport report;
  const Stages stages(progress);
  stages.at(0.f, "session: data");

  // The data source; without it nothing else applies.
  if (!session.builtinScene.empty()) {
    SessionDataReport d{"volume", {},  DataStatus::Ok, "builtin:" + session.builtinScene,
                        {},       true};  // nothing to hash
    d.reference.absolutePath = d.resolvedPath;
    // The scene's own surfaces only when the session says nothing of surfaces or transfer
    // function (a hand-written one); a captured session lists every surface it had.
    const bool sceneSurfaces = session.contextSurfaces.empty() && !session.transferFunction;
    if (!attempt(
            [&] {
              engine.loadBuiltinScene(session.builtinScene, session.builtinResolution,
                                      sceneSurfaces);
            },
            d.message))
      d.status = DataStatus::Missing;
    report.data.push_back(d);
    if (d.status != DataStatus::Ok) return report;
  } else {
    SessionDataReport d =
        check("volume", session.volume, sessionPath, options.check, stages.span(0.f, 0.1f));
    if (usable(d, options) &&
        !attempt([&] { engine.loadVolume(d.resolvedPath, stages.span(0.1f, 0.6f)); }, d.message))
      d.status = DataStatus::Unreadable;
    report.data.push_back(d);
    if (!usable(d, options) || d.status == DataStatus::Unreadable) return report;
  }
  report.sceneLoaded = true;
  if (session.precision != engine.precision())
    report.warnings.push_back(std::string("the session was saved at ") +
                              toString(session.precision) + "; this engine stores " +
                              toString(engine.precision()));
  std::string message;
  auto warnIfFails = [&](const std::string& what, auto&& f) {
    if (!attempt(f, message)) report.warnings.push_back(what + ": " + message);
  };

  stages.at(0.6f, "session: transfer function and importance");
  if (session.transferFunction)
    warnIfFails("transfer function",
                [&] { engine.setTransferFunction(*session.transferFunction); });
  switch (session.importance.kind) {
    case SessionImportance::Kind::None:
    case SessionImportance::Kind::Scene:  // loaded with the built-in scene
      if (session.importance.kind == SessionImportance::Kind::Scene && session.builtinScene.empty())
        report.warnings.push_back("importance: \"scene\" needs a built-in scene");
      break;
    case SessionImportance::Kind::Curve:
      warnIfFails("importance", [&] { engine.setImportanceCurve(session.importance.curve); });
      break;
    case SessionImportance::Kind::Volume: {
      SessionDataReport d = check("importance", session.importance.volume, sessionPath,
                                  options.check, stages.span(0.6f, 0.65f));
      if (usable(d, options) && !attempt([&] { engine.loadImportance(d.resolvedPath); }, d.message))
        d.status = DataStatus::Unreadable;
      report.data.push_back(d);
      break;
    }
    case SessionImportance::Kind::Hotspot:
      warnIfFails("importance", [&] {
        engine.setImportanceHotspot(session.importance.hotspotCentre,
                                    session.importance.hotspotRadius);
      });
      break;
  }

  // Level-set settings first: building a surface's SDF uses them.
  warnIfFails("level-set settings", [&] { engine.setLevelSetSettings(session.levelSet); });
  const size_t surfaces = session.contextSurfaces.size();
  for (size_t i = 0; i < surfaces; ++i) {
    const float from = 0.65f + 0.3f * float(i) / float(surfaces);
    const float to = 0.65f + 0.3f * float(i + 1) / float(surfaces);
    stages.at(from, "session: " + surfaceRole(i));
    ContextSurfaceSpec spec = session.contextSurfaces[i].spec;
    if (!session.contextSurfaces[i].file.empty()) {
      const float checked = from + 0.2f * (to - from);
      SessionDataReport d = check(surfaceRole(i), session.contextSurfaces[i].file, sessionPath,
                                  options.check, stages.span(from, checked));
      if (usable(d, options)) {
        spec.source = session::withSurfaceFile(spec.source, d.resolvedPath);
        if (!attempt([&] { engine.addContextSurface(spec, stages.span(checked, to)); }, d.message))
          d.status = DataStatus::Unreadable;
      }
      report.data.push_back(d);
    } else {
      warnIfFails(surfaceRole(i) + " (" + spec.source + ")",
                  [&] { engine.addContextSurface(spec, stages.span(from, to)); });
    }
  }

  stages.at(0.95f, "session: settings");
  warnIfFails("extinction settings", [&] { engine.setExtinctionSettings(session.extinction); });
  warnIfFails("lens", [&] { engine.setLens(session.lens); });
  if (session.camera) engine.setCamera(*session.camera);
  if (session.light) engine.setLight(*session.light);
  warnIfFails("viewport",
              [&] { engine.setViewportSize(session.render.width, session.render.height); });
  if (session.worldMask) {
    const GridSpec& grid = engine.volume().grid();
    const SessionMask& m = *session.worldMask;
    if (m.dims != grid.dims) {
      report.warnings.push_back("world mask: its dims differ from the volume's; not applied");
    } else {
      warnIfFails("world mask", [&] { engine.setWorldMask(m); });
    }
  }
  engine.setFrozen(session.frozen);
  stages.at(1.f, "session: done");
  return report;
}

}  // namespace visopt
