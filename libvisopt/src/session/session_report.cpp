// Data reports in words, for the CLI's stderr and the workstation's dialogs.
#include "visopt/session.h"

namespace visopt {

std::string describe(const SessionDataReport& d) {
  const DataReference& ref = d.reference;
  const std::string named = !ref.absolutePath.empty() ? ref.absolutePath : ref.relativePath;
  std::string text = d.role + ": " + toString(d.status) + ": ";
  const std::string unverified =
      d.contentVerified ? std::string() : " (its size matches; its content is not yet checked)";
  switch (d.status) {
    case DataStatus::Ok:
      return text + d.resolvedPath + unverified;
    case DataStatus::Moved:
      return text + "not at " + ref.absolutePath + "; found at " + d.resolvedPath + " through " +
             ref.relativePath + unverified;
    case DataStatus::Changed:
      return text + d.resolvedPath +
             " is not the file the session was saved with (its content "
             "hash differs)";
    case DataStatus::Missing:
      if (!d.message.empty()) return text + d.message;
      return text + "not at " + named +
             (ref.relativePath.empty() || ref.absolutePath.empty()
                  ? std::string()
                  : " nor at " + ref.relativePath + " relative to the session's folder");
    case DataStatus::Unreadable:
      return text + d.message;
  }
  return text;
}

}  // namespace visopt
