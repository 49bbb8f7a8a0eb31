#include "engine_controller.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <future>

#include <QMetaObject>
#include <QPointer>

#include <visopt/error.h>

namespace visopt::ws {

namespace {

QImage toQImage(const Image& image) {
  QImage out(image.width, image.height, QImage::Format_RGBA8888);
  if (!out.isNull()) image.writeSrgb8(out.bits(), size_t(out.bytesPerLine()));
  return out;
}

// Frames during optimisation: at most this often, so most of the time goes to iterating.
constexpr int kFrameIntervalMs = 400;
// While following a drag: coarse iterations per call of Engine::followCamera (each call ends
// with one prolongation onto the finest grid and is followed by a preview), and calls per camera
// position. On the default scene a coarse iteration costs ~2 ms against ~50 ms at the finest
// level (test_camera_follow; the probe reports what a drag costs).
constexpr int kFollowIterationsPerCall = 4;
constexpr int kFollowCallsPerCamera = 8;
// In a continuous drag, a follow call after a preview only when the last one ended at least this
// long ago: about every other preview, so that previews keep coming at ~10 per second (a preview
// is ~60 ms, a follow call ~12 ms on the default scene; docs/optimization-benchmarks.md).
constexpr auto kFollowSpacingInDrag = std::chrono::milliseconds(100);
// Longest side of the image the optimisation's frustum grids are sized for while following the
// camera: 128 view rays per side (frustumScale 0.5), about one per voxel column of a 128^3 scene.
constexpr int kOptimizationSide = 256;

}  // namespace

EngineController::EngineController(Precision precision, QObject* parent)
    : QObject(parent), precision_(precision) {
  qRegisterMetaType<FrameInfo>();
  qRegisterMetaType<IterationStats>();
  sinceFrame_.start();
  worker_ = std::thread([this] { workerLoop(); });
}

EngineController::~EngineController() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
    cancel_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void EngineController::deliver(std::function<void()> onUiThread) {
  QMetaObject::invokeMethod(this, std::move(onUiThread), Qt::QueuedConnection);
}

void EngineController::post(const QString& what, Command command) {
  {
    std::lock_guard lock(mutex_);
    tasks_.push_back(
        {what, [c = std::move(command)](Engine& e, const ProgressCallback&) { c(e); }, false});
  }
  wake_.notify_all();
}

void EngineController::postLong(const QString& what, LongCommand command) {
  {
    std::lock_guard lock(mutex_);
    tasks_.push_back({what, std::move(command), true});
  }
  wake_.notify_all();
}

void EngineController::call(const Command& command) {
  auto done = std::make_shared<std::promise<void>>();
  auto result = done->get_future();
  {
    std::lock_guard lock(mutex_);
    tasks_.push_back({QStringLiteral("call"),
                      [command, done](Engine& e, const ProgressCallback&) {
                        try {
                          command(e);
                          done->set_value();
                        } catch (...) {
                          done->set_exception(std::current_exception());
                        }
                      },
                      false});
  }
  wake_.notify_all();
  result.get();
}

std::shared_ptr<const SceneSnapshot> EngineController::snapshot() const {
  std::lock_guard lock(mutex_);
  return snapshot_;
}

void EngineController::refreshSnapshot(Engine& engine, bool volumeChanged) {
  auto snap = std::make_shared<SceneSnapshot>();
  const auto previous = snapshot();
  if (engine.hasVolume()) {
    const Volume& v = engine.volume();
    if (!volumeChanged && previous && previous->volume && previous->volume->grid() == v.grid()) {
      snap->volume = previous->volume;  // same data: no copy, and the histogram stays cached
    } else {
      auto copy = std::make_shared<Volume>();
      copy->name = v.name;
      copy->sourcePath = v.sourcePath;
      copy->scalarType = v.scalarType;
      copy->valueMin = v.valueMin;
      copy->valueMax = v.valueMax;
      copy->normalized = cloneField(v.normalized);
      snap->volume = std::move(copy);
    }
    snap->transferFunction = engine.transferFunction();
    snap->surfaces = engine.contextSurfaces();
    for (size_t i = 0; i < snap->surfaces.size(); ++i) {
      const Field3D* base = engine.contextSurfaceBase(int(i));
      snap->surfaceBases.push_back(base ? std::make_shared<const Field3D>(cloneField(*base))
                                        : nullptr);
    }
  }
  {
    std::lock_guard lock(mutex_);
    snapshot_ = std::move(snap);
  }
  deliver([this] { emit sceneChanged(); });
}

uint64_t EngineController::setCamera(const Camera& camera, bool interacting) {
  uint64_t serial;
  {
    std::lock_guard lock(mutex_);
    camera_ = camera;
    serial = ++cameraSerial_;
    cameraDirty_ = true;
    interacting_ = interacting;
    converged_ = false;
  }
  wake_.notify_all();
  return serial;
}

Camera EngineController::camera() const {
  std::lock_guard lock(mutex_);
  return camera_;
}

void EngineController::setRenderSettings(const RenderSettings& settings) {
  {
    std::lock_guard lock(mutex_);
    render_ = settings;
    oweFrameLocked();
  }
  wake_.notify_all();
}

RenderSettings EngineController::renderSettings() const {
  std::lock_guard lock(mutex_);
  return render_;
}

void EngineController::setViewportSize(int width, int height) {
  {
    std::lock_guard lock(mutex_);
    if (width == viewportWidth_ && height == viewportHeight_) return;
    viewportWidth_ = std::max(16, width);
    viewportHeight_ = std::max(16, height);
    oweFrameLocked();
  }
  wake_.notify_all();
}

void EngineController::requestFrame() {
  {
    std::lock_guard lock(mutex_);
    oweFrameLocked();
  }
  wake_.notify_all();
}

void EngineController::setFollowWhileDragging(bool on) {
  followWhileDragging_ = on;
  wake_.notify_all();
}

void EngineController::setOptimizationRunning(bool running) {
  running_ = running;
  converged_ = false;
  wake_.notify_all();
}

void EngineController::restartOptimization() {
  {
    std::lock_guard lock(mutex_);
    restartPending_ = true;
    converged_ = false;
  }
  wake_.notify_all();
}

bool EngineController::waitIdle(int timeoutMs) {
  std::unique_lock lock(mutex_);
  return idle_.wait_for(lock, std::chrono::milliseconds(timeoutMs),
                        [this] { return !busy_ && !hasWorkLocked(); });
}

bool EngineController::hasWorkLocked() const {
  const bool optimizing =
      running_ && !converged_ && !interacting_ && !clearView_ && snapshot_ && snapshot_->volume;
  const bool following = running_ && interacting_ && followWhileDragging_ && followCallsLeft_ > 0 &&
                         !clearView_ && snapshot_ && snapshot_->volume;
  return !tasks_.empty() || cameraDirty_ || owedFrameLocked() || (previewShown_ && !interacting_) ||
         optimizing || following;
}

void EngineController::runTask(Engine& engine, Task& task) {
  cancel_ = false;
  if (task.isLong) {
    const QString what = task.what;
    deliver([this, what] { emit longWorkStarted(what); });
  }
  ProgressCallback progress = [this](float fraction, const std::string& stage) {
    const QString s = QString::fromStdString(stage);
    deliver([this, s, fraction] { emit progressChanged(s, double(fraction)); });
    return !cancel_.load();
  };
  bool ok = true;
  try {
    task.command(engine, progress);
  } catch (const Error& e) {
    ok = false;
    if (e.kind() != ErrorKind::Cancelled) {
      const QString msg = task.what + QStringLiteral(": ") + QString::fromUtf8(e.what());
      deliver([this, msg] { emit errorOccurred(msg); });
    }
  } catch (const std::exception& e) {
    ok = false;
    const QString msg = task.what + QStringLiteral(": ") + QString::fromUtf8(e.what());
    deliver([this, msg] { emit errorOccurred(msg); });
  }
  if (task.isLong) deliver([this, ok] { emit longWorkFinished(ok); });
  follow_.reset();
  std::lock_guard lock(mutex_);
  oweFrameLocked();
  converged_ = false;
  clearViewRefused_.reset();  // the scene may have changed: ClearView tries again
}

void EngineController::renderFrame(Engine& engine, bool preview) {
  if (renderClearViewFrame(engine, preview)) return;
  RenderSettings settings;
  FrameInfo info;
  uint64_t owedAt;
  {
    std::lock_guard lock(mutex_);
    owedAt = owedSerial_;
    settings = render_;
    settings.width = viewportWidth_;
    settings.height = viewportHeight_;
    info.cameraSerial = renderedSerial_;
    info.camera = camera_;
  }
  settings.preview = preview;
  info.preview = preview;
  RenderStats stats;
  QImage image;
  // A full frame gives way to a newer camera or command (a preview is short).
  const auto abandon = [this] {
    std::lock_guard lock(mutex_);
    return quit_ || cameraDirty_ || !tasks_.empty();
  };
  try {
    const Image rendered =
        engine.render(settings, &stats, preview ? std::function<bool()>() : abandon);
    if (rendered.width == 0) return;  // abandoned: the frame is still owed
    image = toQImage(rendered);
  } catch (const std::exception& e) {
    const QString msg = QStringLiteral("render: ") + QString::fromUtf8(e.what());
    deliver([this, msg] { emit errorOccurred(msg); });
    return;
  }
  info.renderMs = stats.milliseconds;
  frameDone(image, info, preview, owedAt);
}

void EngineController::frameDone(const QImage& image, const FrameInfo& info, bool preview,
                                 uint64_t owedAt) {
  {
    std::lock_guard lock(mutex_);
    previewShown_ = preview;
    // A full frame settles what was owed when it started; a newer request stays owed.
    if (!preview && owedSerial_ == owedAt) frameOwed_ = false;
    if (preview) previewedSerial_ = owedAt;
  }
  sinceFrame_.restart();
  itersSinceFrame_ = 0;
  deliver([this, image, info] { emit frameReady(image, info); });
}

void EngineController::optimizeStep(Engine& engine) {
  const auto interrupt = [this] {
    std::lock_guard lock(mutex_);
    return quit_ || !tasks_.empty() || cameraDirty_ || !running_ || clearView_.has_value();
  };
  const auto report = [this, &engine](const IterationStats& st) {
    const qulonglong bytes = engine.ledger().totalBytes();
    deliver([this, st, bytes] { emit iterationDone(st, bytes); });
  };
  bool restart;
  {
    std::lock_guard lock(mutex_);
    restart = restartPending_;
    restartPending_ = false;
  }
  const auto settle = [this] {
    follow_.reset();
    converged_ = true;
    deliver([this] { emit convergedChanged(true); });
  };
  if (restart) {
    engine.resetOptimization();
    bool interrupted = false;
    engine.optimize(
        [&](const IterationStats& st) {
          report(st);
          if (sinceFrame_.elapsed() > kFrameIntervalMs) renderFrame(engine, false);
          interrupted = interrupt();
          return !interrupted;
        },
        [&] { return interrupted = interrupt(); });
    // The coarse-to-fine schedule ran to its end (each level to its tolerance or cap).
    if (!interrupted) settle();
    std::lock_guard lock(mutex_);
    oweFrameLocked();
    return;
  }
  if (engine.frozen()) {
    converged_ = true;
    return;
  }
  // A newer camera or edit abandons the iteration in flight (it changes nothing), so the worker
  // answers it at once instead of after a whole iteration.
  const auto stats = engine.continueOptimization(1, {}, interrupt);
  if (stats.empty()) return;  // abandoned
  report(stats.back());
  // Following the camera: stop when the energy is still, circles without progress, or after a
  // level's iteration budget (follow_convergence.h).
  if (follow_.add(stats.back(), engine.extinctionSettings())) settle();
  std::lock_guard lock(mutex_);
  oweFrameLocked();
}

bool EngineController::followStep(Engine& engine) {
  {
    std::lock_guard lock(mutex_);
    if (followCallsLeft_ <= 0) return false;
    --followCallsLeft_;
  }
  if (engine.frozen() || !engine.hasImportance()) return false;
  // Not abandoned by a newer camera: a coarse iteration takes milliseconds, and during a drag a
  // newer camera is always on its way, so giving way to it would never let one finish. Commands
  // and pausing still stop it.
  const auto interrupt = [this] {
    std::lock_guard lock(mutex_);
    return quit_ || !tasks_.empty() || !running_ || clearView_.has_value();
  };
  const auto stats = engine.followCamera(kFollowIterationsPerCall, {}, interrupt);
  if (stats.empty()) return false;
  followIterations_ += int(stats.size());
  const qulonglong bytes = engine.ledger().totalBytes();
  const IterationStats last = stats.back();
  deliver([this, last, bytes] { emit iterationDone(last, bytes); });
  return true;
}

bool EngineController::followOnce(Engine& engine) {
  try {
    return followStep(engine);
  } catch (const std::exception& e) {
    running_ = false;
    const QString msg = QStringLiteral("optimisation: ") + QString::fromUtf8(e.what());
    deliver([this, msg] { emit errorOccurred(msg); });
    return false;
  }
}

void EngineController::workerLoop() {
  Engine engine(precision_);
  for (;;) {
    Task task;
    bool haveTask = false;
    {
      std::unique_lock lock(mutex_);
      if (!hasWorkLocked()) {
        busy_ = false;
        idle_.notify_all();
      }
      wake_.wait(lock, [this] { return quit_ || hasWorkLocked(); });
      if (quit_) break;
      busy_ = true;
      if (!tasks_.empty()) {
        task = std::move(tasks_.front());
        tasks_.pop_front();
        haveTask = true;
      }
    }
    if (haveTask) {
      runTask(engine, task);
      continue;
    }

    bool cameraChanged = false, interacting = false, clearViewOn = false;
    Camera cam;
    int w, h;
    {
      std::lock_guard lock(mutex_);
      if (cameraDirty_) {
        cam = camera_;
        renderedSerial_ = cameraSerial_;
        cameraDirty_ = false;
        cameraChanged = true;
        clearViewRefused_.reset();
      }
      interacting = interacting_;
      clearViewOn = clearView_.has_value();
      w = viewportWidth_;
      h = viewportHeight_;
    }
    if (!engine.hasVolume()) {
      std::lock_guard lock(mutex_);
      frameOwed_ = previewShown_ = false;
      continue;
    }
    if (cameraChanged) follow_.reset();
    try {
      if (cameraChanged) engine.setCamera(cam);
      // The frustum grids follow the image's shape, not its pixel count: a large window would
      // otherwise make every iteration (and so the camera's response) slower.
      const float shrink = std::min(1.f, float(kOptimizationSide) / float(std::max(w, h)));
      engine.setViewportSize(std::max(16, int(float(w) * shrink)),
                             std::max(16, int(float(h) * shrink)));
    } catch (const std::exception&) {
    }
    if (cameraChanged && interacting) {
      renderFrame(engine, true);  // the preview first: it is what the user waits for
      {
        std::lock_guard lock(mutex_);
        followCallsLeft_ = kFollowCallsPerCamera;
      }
      // A mouse in motion sends a newer camera before each preview is done: one call of
      // following per preview even then (a few ms; the next preview shows what it opened), or a
      // continuous drag would never follow.
      if (running_ && followWhileDragging_ && !clearViewOn &&
          std::chrono::steady_clock::now() - lastFollowInDrag_ >= kFollowSpacingInDrag) {
        followOnce(engine);
        lastFollowInDrag_ = std::chrono::steady_clock::now();
      }
      continue;
    }
    if (cameraChanged) {
      renderFrame(engine, false);
      continue;
    }
    // While the user drags, the optimisation follows on the coarsest level between previews,
    // each call followed by a preview that shows what it opened; a finest iteration would make
    // the camera wait for it. ClearView's frames do not show the optimisation: it waits while
    // they are on.
    if (running_ && interacting && followWhileDragging_ && !clearViewOn) {
      if (followOnce(engine)) {
        {
          std::lock_guard lock(mutex_);
          if (cameraDirty_ || !tasks_.empty()) continue;  // the newer camera's preview shows it
        }
        renderFrame(engine, true);
        continue;
      }
    }
    const bool optimizing =
        running_ && !converged_ && !interacting && !clearViewOn && engine.hasImportance();
    if (optimizing) {
      try {
        optimizeStep(engine);
      } catch (const std::exception& e) {
        running_ = false;
        const QString msg = QStringLiteral("optimisation: ") + QString::fromUtf8(e.what());
        deliver([this, msg] { emit errorOccurred(msg); });
      }
      {
        // A camera that moved meanwhile (which may have abandoned the step) is answered first,
        // with a preview if the user is dragging, not after a full frame of the old view.
        std::lock_guard lock(mutex_);
        if (cameraDirty_ || !tasks_.empty()) continue;
        interacting = interacting_;
      }
      if (sinceFrame_.elapsed() > kFrameIntervalMs || converged_) renderFrame(engine, interacting);
      continue;
    }
    if (running_ && !engine.hasImportance()) converged_ = true;
    bool owed, previewShown;
    {
      std::lock_guard lock(mutex_);
      owed = owedFrameLocked();
      previewShown = previewShown_;
    }
    if (owed || (previewShown && !interacting)) renderFrame(engine, interacting);
  }
}

}  // namespace visopt::ws
