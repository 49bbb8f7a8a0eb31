// One entry in a MemoryLedger for storage that is not a Field3D (plain device buffers): added on
// construction, removed when the registration is destroyed or replaced. Move-only.
#pragma once

#include <cstddef>
#include <string>
#include <utility>

#include "visopt/memory_ledger.h"

namespace visopt {

class LedgerRegistration {
 public:
  LedgerRegistration() = default;
  LedgerRegistration(MemoryLedger* ledger, std::string name, size_t bytes, std::string precision)
      : ledger_(ledger),
        token_(ledger ? ledger->add(std::move(name), bytes, std::move(precision)) : 0) {}
  ~LedgerRegistration() { release(); }
  LedgerRegistration(LedgerRegistration&& o) noexcept
      : ledger_(std::exchange(o.ledger_, nullptr)), token_(std::exchange(o.token_, 0)) {}
  LedgerRegistration& operator=(LedgerRegistration&& o) noexcept {
    if (this != &o) {
      release();
      ledger_ = std::exchange(o.ledger_, nullptr);
      token_ = std::exchange(o.token_, 0);
    }
    return *this;
  }
  LedgerRegistration(const LedgerRegistration&) = delete;
  LedgerRegistration& operator=(const LedgerRegistration&) = delete;

 private:
  void release() {
    if (ledger_ && token_) ledger_->remove(token_);
    ledger_ = nullptr;
    token_ = 0;
  }
  MemoryLedger* ledger_ = nullptr;
  int token_ = 0;
};

}  // namespace visopt
