#include <cstdio>

#include "cli_common.h"
#include "commands.h"
#include "visopt/volume_io.h"

namespace visopt::cli {

Runner addInfoCommand(CLI::App& app) {
  struct Options {
    std::string file;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  app.add_option("file", o->file, "Volume file or DICOM folder")->required();
  app.add_flag("--json", o->json, "Print one JSON object");
  return [o]() {
    VolumeInfo info = probeVolume(o->file);
    const GridSpec& g = info.grid;
    if (o->json) {
      nlohmann::json j = {
          {"path", info.path},
          {"format", info.format},
          {"dims", {g.dims.x, g.dims.y, g.dims.z}},
          {"spacing", {g.spacing.x, g.spacing.y, g.spacing.z}},
          {"origin", {g.origin.x, g.origin.y, g.origin.z}},
          {"direction",
           {g.direction[0][0], g.direction[1][0], g.direction[2][0], g.direction[0][1],
            g.direction[1][1], g.direction[2][1], g.direction[0][2], g.direction[1][2],
            g.direction[2][2]}},
          {"scalar_type", info.scalarType},
          {"range", {info.valueMin, info.valueMax}},
          {"bytes_on_disk", info.bytesOnDisk},
          {"memory", {{"fp32_bytes", info.bytesFp32}, {"fp16_bytes", info.bytesFp16}}},
          {"warnings", info.warnings}};
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("file:     %s (%s)\n", info.path.c_str(), info.format.c_str());
      std::printf("dims:     %d x %d x %d\n", g.dims.x, g.dims.y, g.dims.z);
      std::printf("spacing:  %g x %g x %g\n", double(g.spacing.x), double(g.spacing.y),
                  double(g.spacing.z));
      std::printf("origin:   %g, %g, %g\n", double(g.origin.x), double(g.origin.y),
                  double(g.origin.z));
      std::printf("type:     %s\n", info.scalarType.c_str());
      std::printf("range:    %g .. %g\n", info.valueMin, info.valueMax);
      std::printf("memory:   %s as fp32, %s as fp16\n", humanBytes(info.bytesFp32).c_str(),
                  humanBytes(info.bytesFp16).c_str());
      for (const std::string& w : info.warnings) std::printf("warning:  %s\n", w.c_str());
    }
    return kOk;
  };
}

Runner addScenesCommand(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  app.add_flag("--json", *json, "Print one JSON object");
  return [json]() {
    if (*json) {
      nlohmann::json list = nlohmann::json::array();
      for (const auto& s : builtinScenes())
        list.push_back({{"name", "builtin:" + s.name},
                        {"description", s.description},
                        {"default", s.name == defaultSceneName()}});
      std::printf("%s\n", nlohmann::json{{"scenes", list}}.dump(2).c_str());
    } else {
      for (const auto& s : builtinScenes())
        std::printf("builtin:%-16s %s%s\n", s.name.c_str(), s.description.c_str(),
                    s.name == defaultSceneName() ? " (default)" : "");
    }
    return kOk;
  };
}

}  // namespace visopt::cli
