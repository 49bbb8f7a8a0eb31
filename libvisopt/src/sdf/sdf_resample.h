// OpenVDB helpers shared by the mesh conversion and the .vdb reader/writer. Internal: only the
// translation units under src/sdf that already use OpenVDB include this.
#pragma once

#include <string>

#include <openvdb/openvdb.h>
#include <glm/glm.hpp>

#include "visopt/field.h"
#include "visopt/grid.h"
#include "visopt/progress.h"

namespace visopt::sdf {

// openvdb::initialize(), once per process (thread-safe).
void initializeOpenVdb();

// The linear index-to-world transform of `grid`'s origin and orientation with `scale` world
// units per index step along each index axis (the grid's spacing, or a cubic voxel size).
openvdb::math::Transform::Ptr linearTransform(const GridSpec& grid, glm::dvec3 scale);

// Samples `vdb` trilinearly at every voxel centre of `out` (world positions through both grids'
// transforms, which must be linear). Values outside the active narrow band are the tree's
// inactive values, whose signs say inside / outside for a level set. With `absolute` the
// sample's magnitude is used; `offset` is subtracted (a thin shell: |u| - d). Progress runs over
// [from, to] under `stage`; a cancel throws Error(Cancelled, "PATH: cancelled").
void resampleToDense(const openvdb::FloatGrid& vdb, Field3D& out, bool absolute, float offset,
                     const ProgressCallback& progress, const std::string& path, float from,
                     float to, const std::string& stage);

}  // namespace visopt::sdf
