#include "io/vtk_quiet.h"

#include <mutex>
#include <vector>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkLogger.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>

namespace visopt::io {

namespace {

// Errors and warnings that reached the output window on this thread while a capture was active
// (messages from objects nobody observes, e.g. the executive or vtkGenericWarningMacro).
thread_local std::vector<std::string>* activeErrors = nullptr;
thread_local std::vector<std::string>* activeWarnings = nullptr;

class CapturingOutputWindow : public vtkOutputWindow {
 public:
  static CapturingOutputWindow* New();
  vtkTypeMacro(CapturingOutputWindow, vtkOutputWindow) void DisplayText(const char* text) override {
    if (!text) return;
    const MessageTypes type = this->GetCurrentMessageType();
    if (activeErrors && type == MESSAGE_TYPE_ERROR) activeErrors->push_back(text);
    if (activeWarnings && (type == MESSAGE_TYPE_WARNING || type == MESSAGE_TYPE_GENERIC_WARNING))
      activeWarnings->push_back(text);
  }
};
vtkStandardNewMacro(CapturingOutputWindow);

void installQuietOutputWindow() {
  static std::once_flag once;
  std::call_once(once, [] {
    vtkSmartPointer<CapturingOutputWindow> window = vtkSmartPointer<CapturingOutputWindow>::New();
    vtkOutputWindow::SetInstance(window);
    // VTK 9 also sends every error and warning to its logger, which prints to stderr.
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  });
}

}  // namespace

struct VtkErrorCapture::Impl {
  vtkObject* watched = nullptr;
  unsigned long errorTag = 0, warningTag = 0;
  vtkSmartPointer<vtkCallbackCommand> callback;
  std::vector<std::string> errors, warnings;
  std::vector<std::string>* previousErrors = nullptr;
  std::vector<std::string>* previousWarnings = nullptr;
};

std::string cleanVtkMessage(const std::string& text) {
  // Keep the last non-empty line, then drop a leading "vtkClass (0x...): ".
  std::string line;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t eol = text.find('\n', pos);
    std::string candidate =
        text.substr(pos, eol == std::string::npos ? std::string::npos : eol - pos);
    if (candidate.find_first_not_of(" \t\r") != std::string::npos) line = candidate;
    if (eol == std::string::npos) break;
    pos = eol + 1;
  }
  size_t marker = line.find("): ");
  if (line.rfind("vtk", 0) == 0 && marker != std::string::npos) line = line.substr(marker + 3);
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
  return line.empty() ? std::string("VTK reported an error") : line;
}

VtkErrorCapture::VtkErrorCapture(vtkObject* watched) : impl_(new Impl) {
  installQuietOutputWindow();
  impl_->watched = watched;
  impl_->callback = vtkSmartPointer<vtkCallbackCommand>::New();
  impl_->callback->SetClientData(impl_);
  impl_->callback->SetCallback([](vtkObject*, unsigned long event, void* client, void* callData) {
    auto* self = static_cast<Impl*>(client);
    if (!callData) return;
    if (event == vtkCommand::ErrorEvent) self->errors.push_back(static_cast<const char*>(callData));
    if (event == vtkCommand::WarningEvent)
      self->warnings.push_back(static_cast<const char*>(callData));
  });
  if (watched) {
    impl_->errorTag = watched->AddObserver(vtkCommand::ErrorEvent, impl_->callback);
    impl_->warningTag = watched->AddObserver(vtkCommand::WarningEvent, impl_->callback);
  }
  impl_->previousErrors = activeErrors;
  impl_->previousWarnings = activeWarnings;
  activeErrors = &impl_->errors;
  activeWarnings = &impl_->warnings;
}

VtkErrorCapture::~VtkErrorCapture() {
  if (impl_->watched) {
    impl_->watched->RemoveObserver(impl_->errorTag);
    impl_->watched->RemoveObserver(impl_->warningTag);
  }
  activeErrors = impl_->previousErrors;
  activeWarnings = impl_->previousWarnings;
  delete impl_;
}

std::optional<std::string> VtkErrorCapture::error() const {
  if (impl_->errors.empty()) return std::nullopt;
  return cleanVtkMessage(impl_->errors.front());
}

std::optional<std::string> VtkErrorCapture::warning() const {
  if (impl_->warnings.empty()) return std::nullopt;
  return cleanVtkMessage(impl_->warnings.front());
}

void VtkErrorCapture::clear() {
  impl_->errors.clear();
  impl_->warnings.clear();
}

}  // namespace visopt::io
