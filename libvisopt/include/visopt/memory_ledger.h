// Every allocated field registers here by name and bytes, so a scene can show what it holds.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace visopt {

struct LedgerEntry {
  std::string name;
  size_t bytes = 0;
  std::string precision;  // "fp32", "fp16", "u8", ...
};

class MemoryLedger {
 public:
  // Returns a token; the entry disappears when the field that holds the token is freed.
  int add(std::string name, size_t bytes, std::string precision);
  void remove(int token);
  std::vector<LedgerEntry> entries() const;  // sorted by name
  size_t totalBytes() const;

 private:
  mutable std::mutex mutex_;
  std::map<int, LedgerEntry> entries_;
  int next_ = 1;
};

}  // namespace visopt
