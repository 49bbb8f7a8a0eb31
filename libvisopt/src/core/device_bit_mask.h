// The world mask as the kernels read it: the words of a BitMask (visopt/bit_mask.h) in memory
// from exec::allocate, 1 bit per voxel, registered in the memory ledger at ceil(voxels / 8)
// bytes. Kernels take its view (core/bit_mask_view.h).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include <glm/glm.hpp>

#include "core/bit_mask_view.h"
#include "core/device_buffer.h"
#include "core/ledger_registration.h"
#include "visopt/bit_mask.h"
#include "visopt/memory_ledger.h"

namespace visopt {

class DeviceBitMask {
 public:
  // All clear.
  DeviceBitMask(glm::ivec3 dims, const std::string& name, MemoryLedger* ledger)
      : dims_(dims), words_(wordCount(dims)), registered_(ledger, name, words_.bytes(), "bit") {
    if (words_.size()) std::memset(words_.data(), 0, words_.size());
  }
  DeviceBitMask(const BitMask& mask, const std::string& name, MemoryLedger* ledger)
      : DeviceBitMask(mask.dims, name, ledger) {
    const size_t n = mask.bits.size() < words_.size() ? mask.bits.size() : words_.size();
    if (n) std::memcpy(words_.data(), mask.bits.data(), n);
  }
  DeviceBitMask(const DeviceBitMask&) = delete;
  DeviceBitMask& operator=(const DeviceBitMask&) = delete;

  glm::ivec3 dims() const { return dims_; }
  size_t bytes() const { return words_.bytes(); }
  uint8_t* words() { return words_.data(); }
  BitMaskView view() const { return BitMaskView{words_.data(), dims_}; }
  BitMask toHost() const {
    BitMask m = BitMask::cleared(dims_);
    if (!m.bits.empty()) std::memcpy(m.bits.data(), words_.data(), m.bits.size());
    return m;
  }

  static size_t wordCount(glm::ivec3 dims) {
    if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) return 0;
    return (size_t(dims.x) * size_t(dims.y) * size_t(dims.z) + 7) / 8;
  }

 private:
  glm::ivec3 dims_;
  DeviceBuffer<uint8_t> words_;
  LedgerRegistration registered_;
};

}  // namespace visopt
