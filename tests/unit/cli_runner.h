// Runs the visopt CLI built with the tests (VISOPT_CLI) and collects its exit code, stdout and
// stderr; stderr goes through a file under VISOPT_TEST_TMP/<subdir>.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace visopt::testing {

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline CliResult runCli(const std::string& args, const std::string& subdir) {
  const std::filesystem::path dir = std::filesystem::path(VISOPT_TEST_TMP) / subdir;
  std::filesystem::create_directories(dir);
  // ctest runs tests as parallel processes: one stderr file per process and call.
  static int calls = 0;
  const std::string errFile =
      (dir / ("stderr-" + std::to_string(getpid()) + "-" + std::to_string(calls++) + ".txt"))
          .string();
  const std::string cmd = std::string(VISOPT_CLI) + " " + args + " 2>" + errFile;
  CliResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err(errFile);
  r.err.assign(std::istreambuf_iterator<char>(err), {});
  return r;
}

}  // namespace visopt::testing
