// Saving and loading session files. Saving is atomic: the text goes to a temporary sibling,
// which is fsynced and renamed over the target (and the folder fsynced), so a crash at any point
// leaves either the old file or the new one, never a mix.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "io/file_util.h"
#include "visopt/error.h"
#include "visopt/session.h"

namespace visopt {

namespace fs = std::filesystem;

namespace {

constexpr std::uintmax_t kMaxSessionBytes = 512u << 20;
std::atomic<SessionSaveHook> saveHook{nullptr};

// The test hook and the VISOPT_SESSION_FAULT crash simulation.
void reachStage(const char* stage) {
  if (SessionSaveHook hook = saveHook.load()) hook(stage);
  const char* fault = std::getenv("VISOPT_SESSION_FAULT");
  if (fault && std::strcmp(fault, stage) == 0) {
    std::fprintf(stderr, "visopt: VISOPT_SESSION_FAULT=%s: exiting mid-save\n", stage);
    std::_Exit(70);
  }
}

[[noreturn]] void failWrite(const std::string& path, const std::string& what, int err) {
  throw Error(ErrorKind::Failure,
              path + ": cannot save the session: " + what + ": " + std::strerror(err));
}

void writeAll(int fd, const char* data, size_t size, const std::string& path) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      failWrite(path, "write", errno);
    }
    data += n;
    size -= size_t(n);
  }
}

// Removes the temporary unless committed.
struct Temporary {
  std::string path;
  int fd = -1;
  int lockFd = -1;  // a duplicate holding the flock until the rename (io::removeStaleTemporaries)
  bool committed = false;
  ~Temporary() {
    if (fd >= 0) ::close(fd);
    if (!committed && !path.empty()) ::unlink(path.c_str());
    if (lockFd >= 0) ::close(lockFd);
  }
};

}  // namespace

void setSessionSaveHook(SessionSaveHook hook) {
  saveHook.store(hook);
}

void saveSession(const Session& session, const std::string& path) {
  const fs::path target = fs::absolute(fs::path(path));
  const fs::path dir = target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throwBadInput(path, "the folder does not exist");
  if (fs::is_directory(target, ec)) throwBadInput(path, "is a folder, not a file");
  const std::string text = sessionToJson(session, target.string());

  Temporary tmp;
  std::string hidden = target.filename().string();
  hidden.insert(hidden.begin(), '.');
  hidden.append(".tmp-");
  // Temporaries of saves that were killed mid-write (no process holds their lock any more).
  io::removeStaleTemporaries(dir.string(), hidden);
  hidden.append("XXXXXX");
  std::string pattern = (dir / hidden).string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  tmp.fd = ::mkstemp(name.data());
  if (tmp.fd < 0) failWrite(path, "cannot create a temporary file next to it", errno);
  tmp.path = name.data();
  ::flock(tmp.fd, LOCK_EX);
  tmp.lockFd = ::dup(tmp.fd);
  // Keep the permissions of the file being replaced; a new one gets rw-r--r--.
  struct stat old {};
  ::fchmod(tmp.fd, ::stat(target.c_str(), &old) == 0 ? (old.st_mode & 07777) : 0644);
  reachStage("temporary-open");

  const size_t half = text.size() / 2;
  writeAll(tmp.fd, text.data(), half, path);
  reachStage("mid-write");
  writeAll(tmp.fd, text.data() + half, text.size() - half, path);
  if (::fsync(tmp.fd) != 0) failWrite(path, "fsync", errno);
  if (::close(tmp.fd) != 0) {
    tmp.fd = -1;
    failWrite(path, "close", errno);
  }
  tmp.fd = -1;
  reachStage("after-write");

  if (std::rename(tmp.path.c_str(), target.c_str()) != 0) failWrite(path, "rename", errno);
  tmp.committed = true;
  // Make the rename itself durable.
  const int dirFd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (dirFd >= 0) {
    ::fsync(dirFd);
    ::close(dirFd);
  }
}

Session loadSession(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throwBadInput(path, "file not found");
  if (fs::is_directory(st)) throwBadInput(path, "is a folder, not a session file");
  if (!fs::is_regular_file(st))
    throwBadInput(path, "is a device, pipe or socket, not a session file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throwBadInput(path, "cannot read its size (" + ec.message() + ")");
  if (size == 0) throwBadInput(path, "file is empty");
  if (size > kMaxSessionBytes) throwBadInput(path, "too large for a session file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throwBadInput(path, std::string("cannot open: ") + std::strerror(errno));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throwBadInput(path, "read error");
  return sessionFromJson(text, path);
}

}  // namespace visopt
