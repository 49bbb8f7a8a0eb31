// availableMemoryBytes(): what this process may still allocate. MemAvailable from /proc/meminfo
// (Linux; else sysconf's free pages), lowered to the address-space and data-segment limits of
// setrlimit (`ulimit -v`, `ulimit -d`, less what the process already maps) and to the cgroup v2
// memory limit of a container (memory.max less memory.current): a request that passes the
// machine's free memory but not the limit the process runs under ended in std::bad_alloc or
// the OOM killer half-way through, instead of a clear refusal up front.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "visopt/volume_io.h"

namespace visopt {

namespace {

constexpr size_t kUnknown = static_cast<size_t>(-1);

// The first number after `key` in /proc/self/status or /proc/meminfo (in KiB there).
size_t kibField(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) != 0) continue;
    std::istringstream fields(line.substr(key.size()));
    unsigned long long kib = 0;
    if (fields >> kib) return static_cast<size_t>(kib) * 1024u;
  }
  return kUnknown;
}

// A whole-file number (cgroup files; "max" means none).
size_t fileNumber(const std::string& path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text == "max") return kUnknown;
  try {
    return static_cast<size_t>(std::stoull(text));
  } catch (const std::exception&) {
    return kUnknown;
  }
}

size_t machineAvailable() {
  const size_t meminfo = kibField("/proc/meminfo", "MemAvailable:");
  if (meminfo != kUnknown) return meminfo;
  const long pages = sysconf(_SC_AVPHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
  if (pages > 0 && pageSize > 0) return static_cast<size_t>(pages) * static_cast<size_t>(pageSize);
  return kUnknown;
}

// Room left under a setrlimit limit, given what the process already uses of it.
size_t underLimit(int resource, size_t used) {
  rlimit limit{};
  if (getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return kUnknown;
  const size_t cap = static_cast<size_t>(limit.rlim_cur);
  return used != kUnknown && used < cap ? cap - used : (used == kUnknown ? cap : 0);
}

// Room left in this process's cgroup (v2), from /proc/self/cgroup's path.
size_t underCgroup() {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("0::", 0) != 0) continue;
    const std::string dir = "/sys/fs/cgroup" + line.substr(3);
    const size_t max = fileNumber(dir + "/memory.max");
    if (max == kUnknown) return kUnknown;
    const size_t current = fileNumber(dir + "/memory.current");
    return current != kUnknown && current < max ? max - current : 0;
  }
  return kUnknown;
}

}  // namespace

// VISOPT_MEMORY_LIMIT_MB: a cap the user sets on what visopt plans to use (a shared machine; the
// fuzz targets, whose sanitizer allocator makes setrlimit unusable). Unset or unreadable: none.
size_t environmentLimit() {
  const char* text = std::getenv("VISOPT_MEMORY_LIMIT_MB");
  if (!text || !*text) return kUnknown;
  char* end = nullptr;
  const unsigned long long mb = std::strtoull(text, &end, 10);
  if (*end != '\0' || mb == 0 || mb > (1ull << 40)) return kUnknown;
  return static_cast<size_t>(mb) << 20;
}

size_t availableMemoryBytes() {
  size_t room = machineAvailable();
  room = std::min(room, environmentLimit());
  room = std::min(room, underLimit(RLIMIT_AS, kibField("/proc/self/status", "VmSize:")));
  room = std::min(room, underLimit(RLIMIT_DATA, kibField("/proc/self/status", "VmData:")));
  room = std::min(room, underCgroup());
  return room;  // kUnknown when nothing is known: do not refuse on memory grounds
}

}  // namespace visopt
