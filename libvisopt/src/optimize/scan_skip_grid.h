// The grid updates' empty-space skip grid (kernels/scan_skip.h), built from the current mu,
// importance and context surfaces; its buffers are reused while the grid's size stays.
#pragma once

#include <cstdint>

#include "core/device_buffer.h"
#include "core/ledger_registration.h"
#include "kernels/scan_skip.h"
#include "kernels/surface_set.h"
#include "visopt/field.h"

namespace visopt {

struct ScanSkipStorage {
  DeviceBuffer<uint8_t> own, flags;
  ScanSkipGrid grid;
  LedgerRegistration registered;  // "scan-skip-grid": both buffers' bytes
};

// mu, importance and the surfaces' phi on one grid (otherwise out.grid is left empty: no skipping).
// The buffers are listed in `ledger` (may be null) while they exist.
void buildScanSkipGrid(const Field3D& mu, const Field3D& importance, const SurfaceSet& surfaces,
                       ScanSkipStorage& out, MemoryLedger* ledger = nullptr);

}  // namespace visopt
