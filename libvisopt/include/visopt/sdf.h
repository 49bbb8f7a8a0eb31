// Context surfaces as signed distance fields (Himmler & Günther 2026, §III-B): inside negative,
// outside positive, |grad phi| = 1, in world units. A surface is used filled or as a thin shell
// around its zero level set, phi_shell = |phi| - d (Eq. 26): the shell reaches d to either side.
#pragma once

#include <cstddef>
#include <string>

#include "visopt/field.h"
#include "visopt/grid.h"
#include "visopt/precision.h"
#include "visopt/progress.h"
#include "visopt/volume.h"

namespace visopt {

class MemoryLedger;

// What loading a mesh found and repaired.
struct MeshReport {
  std::string path;
  size_t vertices = 0, faces = 0;
  size_t duplicateVerticesMerged = 0, degenerateFacesRemoved = 0;
  size_t boundaryEdges = 0, nonManifoldEdges = 0;
  bool closed = false, manifold = false;
  float bboxMin[3] = {0, 0, 0}, bboxMax[3] = {0, 0, 0};
};

struct MeshSdfOptions {
  bool filled = true;          // a filled SDF needs a closed manifold mesh
  float shellThickness = 0.f;  // d of Eq. 26 in world units, when !filled (> 0)
  // The grid: `like` when its dims are set (e.g. a volume's grid), otherwise a grid of cubic
  // voxels of `voxelSize` around the mesh's bounding box plus `paddingVoxels` on every side.
  GridSpec like{glm::ivec3(0)};
  float voxelSize = 0.f;
  int paddingVoxels = 3;
};

// Loads an OBJ / PLY / OFF / STL mesh, merges duplicate vertices and drops degenerate faces,
// checks closedness and manifoldness, and computes its signed (filled) or unsigned-minus-half-
// thickness (shell) distance on the grid. Refuses (Error BadInput, one line naming the file) an
// empty, truncated or unreadable file, NaN/Inf vertices, and a filled SDF from an open or
// non-manifold mesh (the message suggests a thin shell). Reports progress; honours cancellation.
Field3D sdfFromMesh(const std::string& path, const MeshSdfOptions& options, Precision precision,
                    MemoryLedger* ledger, MeshReport* report = nullptr,
                    const ProgressCallback& progress = {});

// Reads the first float grid of an OpenVDB file as a dense SDF: on `like` when its dims are set
// (resampled; beyond the file's narrow band the background value's sign is kept), otherwise on
// the grid's own active bounding box. BadInput for a missing, corrupt or grid-less file.
Field3D readSdfVdb(const std::string& path, const GridSpec& like, Precision precision,
                   MemoryLedger* ledger);
// Writes a dense SDF as an OpenVDB level set (narrow band of `bandVoxels` voxels), atomically.
void writeSdfVdb(const Field3D& sdf, const std::string& path, float bandVoxels = 3.f);

}  // namespace visopt
