// availableMemoryBytes(): MemAvailable from /proc/meminfo (Linux), else sysconf's free pages.
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

#include "visopt/volume_io.h"

namespace visopt {

size_t availableMemoryBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string line;
  while (std::getline(meminfo, line)) {
    if (line.rfind("MemAvailable:", 0) != 0) continue;
    std::istringstream fields(line.substr(13));
    unsigned long long kib = 0;
    if (fields >> kib) return static_cast<size_t>(kib) * 1024u;
  }
  long pages = sysconf(_SC_AVPHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
  if (pages > 0 && pageSize > 0) return static_cast<size_t>(pages) * static_cast<size_t>(pageSize);
  return static_cast<size_t>(-1);  // unknown: do not refuse on memory grounds
}

}  // namespace visopt
