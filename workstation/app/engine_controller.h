// The Engine on its own thread. The UI never calls the Engine: it posts commands that the worker
// runs between optimisation iterations, in order, and receives frames, statistics, progress and
// errors as signals on the UI thread. While optimisation runs, the worker alternates one
// iteration at the current camera (Himmler & Günther 2026, §III-F "Navigation": the optimisation
// follows the camera, warm-started from the current mu) with a render; while the user drags the
// camera it renders low-resolution previews first and the full image once the camera rests.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <QElapsedTimer>
#include <QImage>
#include <QObject>
#include <QString>

#include <visopt/engine.h>

#include "follow_convergence.h"
#include "scene_snapshot.h"

namespace visopt::ws {

// A rendered frame and where it came from.
struct FrameInfo {
  bool preview = false;
  double renderMs = 0.0;
  uint64_t cameraSerial = 0;  // the setCamera call this frame shows (latency measurement)
  Camera camera;
};

class EngineController : public QObject {
  Q_OBJECT
 public:
  using Command = std::function<void(Engine&)>;

  explicit EngineController(Precision precision = Precision::FP32, QObject* parent = nullptr);
  ~EngineController() override;

  Precision precision() const { return precision_; }

  // Runs `command` on the worker before the next iteration. An Error it throws is reported as
  // errorOccurred("WHAT: message") (and as a dialog by the main window).
  void post(const QString& what, Command command);
  // Long work (loading, mesh conversion) with progress and cancel: `command` gets a progress
  // callback that reports through progressChanged and returns false once cancel() was called.
  using LongCommand = std::function<void(Engine&, const ProgressCallback&)>;
  void postLong(const QString& what, LongCommand command);
  void cancelLongWork() { cancel_ = true; }
  // Runs `command` on the worker and waits for it (session capture, tests). Rethrows its error.
  void call(const Command& command);

  // The scene changed in a way the UI's snapshot must follow (data, TF, surfaces): commands
  // that change it call this from the worker; the main window rarely needs it directly.
  // `volumeChanged`: new data was loaded (the scalars are copied again; otherwise the previous
  // snapshot's copy is kept).
  void refreshSnapshot(Engine& engine, bool volumeChanged = false);
  std::shared_ptr<const SceneSnapshot> snapshot() const;

  // Camera: `interacting` true while the user drags (preview frames); false renders full size.
  // Returns the serial the matching frame will carry.
  uint64_t setCamera(const Camera& camera, bool interacting);
  Camera camera() const;
  void setRenderSettings(const RenderSettings& settings);
  RenderSettings renderSettings() const;
  void setViewportSize(int width, int height);
  void requestFrame();

  // Continuous optimisation (follows the camera). Starting it on a fresh scene runs the
  // coarse-to-fine schedule first; moving the camera then continues at the finest level.
  void setOptimizationRunning(bool running);
  bool optimizationRunning() const { return running_; }
  void restartOptimization();  // from mu_bar, coarse to fine

  // Waits until the worker has nothing left to do right now: no command queued, no frame owed
  // (tests and --screenshot). Returns false on timeout.
  bool waitIdle(int timeoutMs);
  // True once an optimisation has converged at the finest level since the last restart.
  bool converged() const { return converged_; }

 signals:
  void frameReady(const QImage& image, const visopt::ws::FrameInfo& info);
  void iterationDone(const visopt::IterationStats& stats, qulonglong ledgerBytes);
  void sceneChanged();  // a new snapshot is available
  void errorOccurred(const QString& message);
  void longWorkStarted(const QString& what);
  void progressChanged(const QString& stage, double fraction);
  void longWorkFinished(bool ok);
  void convergedChanged(bool converged);

 private:
  struct Task {
    QString what;
    LongCommand command;
    bool isLong = false;
  };
  void workerLoop();
  bool hasWorkLocked() const;
  void runTask(Engine& engine, Task& task);
  void optimizeStep(Engine& engine);
  void renderFrame(Engine& engine, bool preview);
  void deliver(std::function<void()> onUiThread);  // queued to the UI thread

  const Precision precision_;
  std::thread worker_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<Task> tasks_;
  bool quit_ = false;
  bool busy_ = false;

  // Camera and view state, owned by the UI, picked up by the worker.
  Camera camera_;
  uint64_t cameraSerial_ = 0, renderedSerial_ = 0;
  bool cameraDirty_ = false;
  bool interacting_ = false;
  bool frameOwed_ = false;     // something changed since the last full frame
  bool previewShown_ = false;  // the last frame was a preview
  RenderSettings render_;
  int viewportWidth_ = 512, viewportHeight_ = 512;

  std::atomic<bool> running_{false};
  std::atomic<bool> cancel_{false};
  std::atomic<bool> converged_{false};
  bool restartPending_ = true;  // next optimisation step runs the multigrid schedule
  int itersSinceFrame_ = 0;
  // Worker-only: convergence while following the camera.
  FollowConvergence follow_;
  QElapsedTimer sinceFrame_;

  std::shared_ptr<const SceneSnapshot> snapshot_;
};

}  // namespace visopt::ws

Q_DECLARE_METATYPE(visopt::ws::FrameInfo)
Q_DECLARE_METATYPE(visopt::IterationStats)
