// A dense scalar field on a grid, stored as fp32 or fp16 (a runtime choice per field).
// Storage comes from the execution layer, so the same memory is reachable from either backend.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "visopt/grid.h"
#include "visopt/precision.h"

namespace visopt {

class MemoryLedger;

class Field3D {
 public:
  Field3D() = default;
  // Allocates uninitialised storage; registers in `ledger` (may be null) under `name`.
  Field3D(std::string name, const GridSpec& grid, Precision precision,
          MemoryLedger* ledger = nullptr);
  ~Field3D();
  Field3D(Field3D&&) noexcept;
  Field3D& operator=(Field3D&&) noexcept;
  Field3D(const Field3D&) = delete;
  Field3D& operator=(const Field3D&) = delete;

  bool empty() const { return data_ == nullptr; }
  // Renames the field and moves its ledger entry to `ledger` (may be null) under the new name.
  void rename(std::string name, MemoryLedger* ledger);
  const std::string& name() const { return name_; }
  const GridSpec& grid() const { return grid_; }
  Precision precision() const { return precision_; }
  size_t size() const { return grid_.voxelCount(); }
  size_t bytes() const { return size() * bytesPerValue(precision_); }

  // Host access, converting on the fly. Kernels use the internal views instead.
  float get(size_t i) const;
  void set(size_t i, float v);
  void fill(float v);
  void* raw() { return data_; }
  const void* raw() const { return data_; }

 private:
  void release();
  std::string name_;
  GridSpec grid_;
  Precision precision_ = Precision::FP32;
  void* data_ = nullptr;
  MemoryLedger* ledger_ = nullptr;
  int ledgerToken_ = 0;
};

}  // namespace visopt
