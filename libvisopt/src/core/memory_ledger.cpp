#include "visopt/memory_ledger.h"

#include <algorithm>

namespace visopt {

int MemoryLedger::add(std::string name, size_t bytes, std::string precision) {
  std::lock_guard lock(mutex_);
  int token = next_++;
  entries_[token] = LedgerEntry{std::move(name), bytes, std::move(precision)};
  return token;
}

void MemoryLedger::remove(int token) {
  std::lock_guard lock(mutex_);
  entries_.erase(token);
}

std::vector<LedgerEntry> MemoryLedger::entries() const {
  std::lock_guard lock(mutex_);
  std::vector<LedgerEntry> out;
  for (auto& [token, e] : entries_) out.push_back(e);
  std::sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.name < b.name; });
  return out;
}

size_t MemoryLedger::totalBytes() const {
  std::lock_guard lock(mutex_);
  size_t total = 0;
  for (auto& [token, e] : entries_) total += e.bytes;
  return total;
}

}  // namespace visopt
