// Keeps VTK quiet and turns its complaints into our messages. VTK reports reader errors through
// vtkErrorMacro, which goes to an ErrorEvent observer when the object has one and otherwise to
// the global vtkOutputWindow. VtkErrorCapture observes one object and also installs (once per
// process) an output window that records text instead of printing it, so nothing VTK says
// reaches the terminal; the first error seen becomes the "problem" part of our message.
#pragma once

#include <optional>
#include <string>

class vtkObject;

namespace visopt::io {

class VtkErrorCapture {
 public:
  explicit VtkErrorCapture(vtkObject* watched);
  ~VtkErrorCapture();
  VtkErrorCapture(const VtkErrorCapture&) = delete;
  VtkErrorCapture& operator=(const VtkErrorCapture&) = delete;

  // The first error reported since construction (or the last clear()), reduced to one line.
  std::optional<std::string> error() const;
  // The first warning, likewise (some readers only warn about short data).
  std::optional<std::string> warning() const;
  void clear();

 private:
  struct Impl;
  Impl* impl_;
};

// Reduces VTK's multi-line "ERROR: In file, line N\nvtkClass (0x...): text" to "text".
std::string cleanVtkMessage(const std::string& text);

}  // namespace visopt::io
