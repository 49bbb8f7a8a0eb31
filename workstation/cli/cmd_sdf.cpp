// visopt sdf: a triangle mesh -> a signed distance field (filled or thin shell) in a .vdb file.
#include <chrono>
#include <cmath>
#include <cstdio>

#include "cli_common.h"
#include "commands.h"
#include "visopt/error.h"
#include "visopt/sdf.h"
#include "visopt/volume_io.h"

namespace visopt::cli {

Runner addSdfCommand(CLI::App& app) {
  struct Options {
    std::string mesh, like, out;
    bool filled = false, json = false;
    float shell = 0.f, voxel = 0.f;
    int padding = 3;
  };
  auto o = std::make_shared<Options>();
  app.add_option("--mesh", o->mesh, "Triangle mesh: .obj, .ply, .off or .stl")->required();
  CLI::Option* filled = app.add_flag("--filled", o->filled, "Filled SDF (needs a closed mesh)");
  CLI::Option* shell =
      app.add_option("--shell", o->shell, "Thin shell reaching D (world units) to either side")
          ->default_str("");
  CLI::Option* like =
      app.add_option("--like", o->like, "Sample on the grid of this volume (dims, spacing, ...)");
  CLI::Option* voxel =
      app.add_option("--voxel", o->voxel, "Cubic voxel size in world units")->default_str("");
  CLI::Option* padding =
      app.add_option("--padding", o->padding, "Voxels around the mesh's bounding box");
  app.add_option("--out", o->out, "Output OpenVDB file (.vdb)")->required();
  app.add_flag("--json", o->json, "Print one JSON object");

  return [o, filled, shell, like, voxel, padding]() {
    if ((filled->count() > 0) == (shell->count() > 0))
      throw Error(ErrorKind::Usage, "give exactly one of --filled or --shell D");
    if (shell->count() > 0 && !(o->shell > 0.f && std::isfinite(o->shell)))
      throw Error(ErrorKind::Usage, "--shell: the thickness must be > 0");
    if (like->count() > 0 && (voxel->count() > 0 || padding->count() > 0))
      throw Error(ErrorKind::Usage, "give either --like VOLUME or --voxel SIZE [--padding P]");
    if (like->count() == 0 && voxel->count() == 0)
      throw Error(ErrorKind::Usage, "give --like VOLUME or --voxel SIZE");
    if (voxel->count() > 0 && !(o->voxel > 0.f && std::isfinite(o->voxel)))
      throw Error(ErrorKind::Usage, "--voxel: the size must be > 0");
    if (o->padding < 0) throw Error(ErrorKind::Usage, "--padding: must be >= 0");

    const auto start = std::chrono::steady_clock::now();
    MeshSdfOptions options;
    options.filled = o->filled;
    options.shellThickness = o->shell;
    options.voxelSize = o->voxel;
    options.paddingVoxels = o->padding;
    if (!o->like.empty()) options.like = probeVolume(o->like).grid;

    ProgressCallback progress = [](float fraction, const std::string& stage) {
      std::fprintf(stderr, "\rsdf: %-10s %3d%%", stage.c_str(), int(fraction * 100.f + 0.5f));
      std::fflush(stderr);
      return true;
    };
    MeshReport report;
    Field3D sdf;
    try {
      sdf = sdfFromMesh(o->mesh, options, Precision::FP32, nullptr, &report, progress);
      std::fprintf(stderr, "\n");
    } catch (...) {
      std::fprintf(stderr, "\n");
      throw;
    }
    writeSdfVdb(sdf, o->out);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

    const GridSpec& g = sdf.grid();
    if (o->json) {
      nlohmann::json j = {
          {"mesh",
           {{"path", report.path},
            {"vertices", report.vertices},
            {"faces", report.faces},
            {"duplicate_vertices_merged", report.duplicateVerticesMerged},
            {"degenerate_faces_removed", report.degenerateFacesRemoved},
            {"boundary_edges", report.boundaryEdges},
            {"non_manifold_edges", report.nonManifoldEdges},
            {"closed", report.closed},
            {"manifold", report.manifold},
            {"bbox_min", {report.bboxMin[0], report.bboxMin[1], report.bboxMin[2]}},
            {"bbox_max", {report.bboxMax[0], report.bboxMax[1], report.bboxMax[2]}}}},
          {"mode", o->filled ? "filled" : "shell"},
          {"shell_thickness", o->filled ? 0.f : o->shell},
          {"grid",
           {{"dims", {g.dims.x, g.dims.y, g.dims.z}},
            {"spacing", {g.spacing.x, g.spacing.y, g.spacing.z}},
            {"origin", {g.origin.x, g.origin.y, g.origin.z}}}},
          {"time_ms", ms},
          {"out", o->out}};
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("mesh:     %s: %zu vertices, %zu faces, %s, %s\n", report.path.c_str(),
                  report.vertices, report.faces, report.closed ? "closed" : "open",
                  report.manifold ? "manifold" : "non-manifold");
      std::printf("repaired: %zu duplicate vertices merged, %zu degenerate faces removed\n",
                  report.duplicateVerticesMerged, report.degenerateFacesRemoved);
      std::printf("grid:     %d x %d x %d, spacing %g x %g x %g\n", g.dims.x, g.dims.y, g.dims.z,
                  double(g.spacing.x), double(g.spacing.y), double(g.spacing.z));
      std::printf("wrote:    %s (%.0f ms)\n", o->out.c_str(), ms);
    }
    return kOk;
  };
}

}  // namespace visopt::cli
