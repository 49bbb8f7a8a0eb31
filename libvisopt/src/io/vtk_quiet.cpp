#include "io/vtk_quiet.h"

#include <mutex>
#include <vector>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>

namespace visopt::io {

namespace {

// Errors that reached the output window on this thread while a capture was active.
thread_local std::vector<std::string>* activeLog = nullptr;

class CapturingOutputWindow : public vtkOutputWindow {
 public:
  static CapturingOutputWindow* New();
  vtkTypeMacro(CapturingOutputWindow, vtkOutputWindow);
  void DisplayText(const char* text) override {
    if (activeLog && text && this->GetCurrentMessageType() == MESSAGE_TYPE_ERROR)
      activeLog->push_back(text);
  }
};
vtkStandardNewMacro(CapturingOutputWindow);

void installQuietOutputWindow() {
  static std::once_flag once;
  std::call_once(once, [] {
    vtkSmartPointer<CapturingOutputWindow> window = vtkSmartPointer<CapturingOutputWindow>::New();
    vtkOutputWindow::SetInstance(window);
  });
}

}  // namespace

struct VtkErrorCapture::Impl {
  vtkObject* watched = nullptr;
  unsigned long errorTag = 0, warningTag = 0;
  vtkSmartPointer<vtkCallbackCommand> callback;
  std::vector<std::string> errors;
  std::vector<std::string>* previousLog = nullptr;
};

std::string cleanVtkMessage(const std::string& text) {
  // Keep the last non-empty line, then drop a leading "vtkClass (0x...): ".
  std::string line;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t eol = text.find('\n', pos);
    std::string candidate = text.substr(pos, eol == std::string::npos ? std::string::npos : eol - pos);
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
    if (event == vtkCommand::ErrorEvent && callData)
      self->errors.push_back(static_cast<const char*>(callData));
  });
  if (watched) {
    impl_->errorTag = watched->AddObserver(vtkCommand::ErrorEvent, impl_->callback);
    impl_->warningTag = watched->AddObserver(vtkCommand::WarningEvent, impl_->callback);
  }
  impl_->previousLog = activeLog;
  activeLog = &impl_->errors;
}

VtkErrorCapture::~VtkErrorCapture() {
  if (impl_->watched) {
    impl_->watched->RemoveObserver(impl_->errorTag);
    impl_->watched->RemoveObserver(impl_->warningTag);
  }
  activeLog = impl_->previousLog;
  delete impl_;
}

std::optional<std::string> VtkErrorCapture::error() const {
  if (impl_->errors.empty()) return std::nullopt;
  return cleanVtkMessage(impl_->errors.front());
}

void VtkErrorCapture::clear() { impl_->errors.clear(); }

}  // namespace visopt::io
