// Errors are values a user can read: every failure the library reports carries a kind
// (so the CLI can map it to an exit code) and a one-line message naming the file and the problem.
#pragma once

#include <stdexcept>
#include <string>

namespace visopt {

enum class ErrorKind {
  Usage,      // a caller asked for something that makes no sense (bad option, bad parameter)
  BadInput,   // a file or value given by the user is unreadable, inconsistent or out of range
  Cancelled,  // the user cancelled long work
  Failure,    // anything else: out of memory, a backend failure, a bug
};

class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  ErrorKind kind() const { return kind_; }

 private:
  ErrorKind kind_;
};

// "FILE: problem" — the format every bad-input message uses.
[[noreturn]] inline void throwBadInput(const std::string& file, const std::string& problem) {
  throw Error(ErrorKind::BadInput, file.empty() ? problem : file + ": " + problem);
}

}  // namespace visopt
