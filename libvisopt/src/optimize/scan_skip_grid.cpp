#include "optimize/scan_skip_grid.h"

#include "exec/parallel.h"

namespace visopt {

void buildScanSkipGrid(const Field3D& mu, const Field3D& importance, const SurfaceSet& surfaces,
                       ScanSkipStorage& out, MemoryLedger* ledger) {
  const glm::ivec3 voxels = mu.grid().dims;
  bool sameGrid = importance.grid().dims == voxels;
  for (int s = 0; s < surfaces.count; ++s) sameGrid = sameGrid && surfaces.phi[s].dims == voxels;
  if (!sameGrid) {  // not the optimiser's case: no skipping
    out.grid = ScanSkipGrid{};
    return;
  }
  const glm::ivec3 bricks = scanSkipBricks(voxels);
  const int64_t n = int64_t(bricks.x) * bricks.y * bricks.z;
  if (out.flags.size() != size_t(n)) {
    out.own = DeviceBuffer<uint8_t>(size_t(n));
    out.flags = DeviceBuffer<uint8_t>(size_t(n));
    out.registered = LedgerRegistration(ledger, "scan-skip-grid", 2 * size_t(n), "u8");
  }
  exec::parallelFor(
      "grid updates: skip grid", n,
      ScanSkipOwnFlags{FieldView(mu), FieldView(importance), surfaces, bricks, out.own.data()});
  exec::parallelFor("grid updates: skip grid", n,
                    ScanSkipDilate{bricks, out.own.data(), out.flags.data()});
  out.grid.flags = out.flags.data();
  out.grid.bricks = bricks;
  out.grid.voxels = voxels;
}

}  // namespace visopt
