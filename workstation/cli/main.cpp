// visopt: the command-line face of libvisopt. Exit codes: 0 success, 1 usage error, 2 bad input,
// 3 other failures. With --json a subcommand prints exactly one JSON object on stdout.
#include <cstdio>
#include <map>

#include <CLI/CLI.hpp>

#include "cli_common.h"
#include "commands.h"
#include "visopt/error.h"

int main(int argc, char** argv) {
  using namespace visopt::cli;
  CLI::App app{"visopt: visibility optimization for direct and indirect volume rendering"};
  app.require_subcommand(1);
  // Every option's help shows its default (the value it holds before parsing); subcommands
  // inherit this.
  app.option_defaults()->always_capture_default();
  std::map<CLI::App*, Runner> runners;
  auto add = [&](Runner (*f)(CLI::App&), const char* name, const char* help) {
    CLI::App* sub = app.add_subcommand(name, help);
    runners[sub] = f(*sub);
  };
  add(addInfoCommand, "info", "Describe a volume file: dims, spacing, origin, type, range, memory");
  add(addScenesCommand, "scenes", "List the built-in scenes");
  add(addRenderCommand, "render", "Render a volume or built-in scene to a PNG");
  add(addOptimizeCommand, "optimize", "Optimise the extinction so the important parts show");
  add(addCompareCommand, "compare", "The four methods of Fig. 10 side by side");
  add(addSdfCommand, "sdf", "Convert a triangle mesh to a signed distance field (.vdb)");
  add(addSessionInfoCommand, "session-info", "Describe a session file and check its data files");
  add(addImageDiffCommand, "image-diff", "PSNR, SSIM and FLIP of two images of the same size");
  add(addMomentsCommand, "moments",
      "Moment images (Rapp et al. 2022): generate, render with any transfer function, info");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kUsage;
  }
  try {
    for (auto& [sub, run] : runners)
      if (sub->parsed()) return run();
  } catch (const visopt::Error& e) {
    std::fprintf(stderr, "visopt: %s\n", e.what());
    switch (e.kind()) {
      case visopt::ErrorKind::Usage:
        return kUsage;
      case visopt::ErrorKind::BadInput:
        return kBadInput;
      default:
        return kFailure;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "visopt: %s\n", e.what());
    return kFailure;
  }
  return kUsage;
}
