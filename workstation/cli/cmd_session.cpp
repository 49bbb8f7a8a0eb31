// visopt session-info FILE: what a session holds and whether its data files are where it says.
#include <cstdio>

#include "clearview_spec.h"
#include "cli_common.h"
#include "commands.h"
#include "visopt/session.h"

namespace visopt::cli {

namespace {

nlohmann::json referenceJson(const SessionDataReport& d) {
  return {{"role", d.role},
          {"status", toString(d.status)},
          {"absolute", d.reference.absolutePath},
          {"relative", d.reference.relativePath},
          {"resolved", d.resolvedPath},
          {"sha256", d.reference.sha256},
          {"bytes", d.reference.bytes},
          {"content_verified", d.contentVerified}};
}

}  // namespace

Runner addSessionInfoCommand(CLI::App& app) {
  struct Options {
    std::string file;
    bool json = false;
    bool sizesOnly = false;
  };
  auto o = std::make_shared<Options>();
  app.add_option("file", o->file, "Session file")->required();
  app.add_flag("--json", o->json, "Print one JSON object");
  app.add_flag("--sizes-only", o->sizesOnly,
               "Compare the data files' sizes with the recorded ones, without reading them "
               "(default: their content hashes are compared too)");
  return [o]() {
    const Session s = loadSession(o->file);
    const std::vector<SessionDataReport> data =
        checkSessionData(s, o->file, o->sizesOnly ? DataCheck::Size : DataCheck::Content);
    size_t maskSet = 0;
    if (s.worldMask)
      for (size_t i = 0; i < s.worldMask->voxelCount(); ++i) maskSet += s.worldMask->get(i);
    const std::string source = s.builtinScene.empty() ? s.volume.absolutePath
                                                      : "builtin:" + s.builtinScene + " at " +
                                                            std::to_string(s.builtinResolution);
    if (o->json) {
      nlohmann::json files = nlohmann::json::array();
      for (const auto& d : data) files.push_back(referenceJson(d));
      nlohmann::json settings = nlohmann::json::parse(sessionToJson(s, o->file));
      if (settings.contains("worldMask")) settings["worldMask"].erase("data");
      nlohmann::json j = {
          {"command", "session-info"},
          {"path", o->file},
          {"file_version", s.version},
          {"format_version", kSessionFormatVersion},
          {"source", source},
          {"precision", toString(s.precision)},
          {"transfer_function", s.transferFunction ? s.transferFunction->name : ""},
          {"importance", toString(s.importance.kind)},
          {"context_surfaces", s.contextSurfaces.size()},
          {"frozen", s.frozen},
          {"world_mask", s.worldMask ? nlohmann::json{{"dims",
                                                       {s.worldMask->dims.x, s.worldMask->dims.y,
                                                        s.worldMask->dims.z}},
                                                      {"voxels_set", maskSet}}
                                     : nlohmann::json(nullptr)},
          {"data", files},
          {"session", settings}};
      std::printf("%s\n", j.dump(2).c_str());
      return kOk;
    }
    std::printf("session:     %s (format version %d%s)\n", o->file.c_str(), s.version,
                s.version < kSessionFormatVersion ? ", migrated on load" : "");
    std::printf("data:        %s\n", source.c_str());
    std::printf("precision:   %s\n", toString(s.precision));
    std::printf("transfer fn: %s\n",
                s.transferFunction ? s.transferFunction->name.c_str() : "(the data's default)");
    if (s.importance.kind == ImportanceKind::Hotspot)
      std::printf("importance:  hotspot, a ball of radius %g about %g,%g,%g\n",
                  double(s.importance.hotspotRadius), double(s.importance.hotspotCentre.x),
                  double(s.importance.hotspotCentre.y), double(s.importance.hotspotCentre.z));
    else
      std::printf("importance:  %s\n", toString(s.importance.kind));
    for (size_t i = 0; i < s.contextSurfaces.size(); ++i)
      std::printf("surface %zu:   %s%s\n", i + 1, s.contextSurfaces[i].spec.source.c_str(),
                  s.contextSurfaces[i].spec.visible ? "" : " (hidden)");
    if (s.camera)
      std::printf("camera:      eye %g,%g,%g  target %g,%g,%g\n", double(s.camera->eye.x),
                  double(s.camera->eye.y), double(s.camera->eye.z), double(s.camera->target.x),
                  double(s.camera->target.y), double(s.camera->target.z));
    std::printf("frozen:      %s\n", s.frozen ? "yes" : "no");
    if (s.clearView)
      std::printf(
          "hotspot:     %s over %s, %s, shaders %s / %s, size %s\n",
          describeClearViewLayer(s.clearView->context).c_str(),
          describeClearViewLayer(s.clearView->focus).c_str(), toString(s.clearView->measure),
          toString(s.clearView->contextShader), toString(s.clearView->focusShader),
          s.clearView->size > 0.f ? std::to_string(s.clearView->size).c_str() : "automatic");
    if (s.worldMask)
      std::printf("world mask:  %d x %d x %d, %zu voxels set\n", s.worldMask->dims.x,
                  s.worldMask->dims.y, s.worldMask->dims.z, maskSet);
    for (const auto& d : data) std::printf("file:        %s\n", describe(d).c_str());
    return kOk;
  };
}

}  // namespace visopt::cli
