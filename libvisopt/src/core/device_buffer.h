// A typed buffer in memory reachable from the active backend (see exec::allocate).
#pragma once

#include <cstddef>
#include <utility>

#include "exec/parallel.h"

namespace visopt {

template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  explicit DeviceBuffer(size_t n) : n_(n), p_(static_cast<T*>(exec::allocate(n * sizeof(T)))) {}
  ~DeviceBuffer() { exec::deallocate(p_); }
  DeviceBuffer(DeviceBuffer&& o) noexcept
      : n_(std::exchange(o.n_, 0)), p_(std::exchange(o.p_, nullptr)) {}
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    std::swap(n_, o.n_);
    std::swap(p_, o.p_);
    return *this;
  }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;

  T* data() { return p_; }
  const T* data() const { return p_; }
  size_t size() const { return n_; }
  size_t bytes() const { return n_ * sizeof(T); }
  T& operator[](size_t i) { return p_[i]; }
  const T& operator[](size_t i) const { return p_[i]; }

 private:
  size_t n_ = 0;
  T* p_ = nullptr;
};

}  // namespace visopt
