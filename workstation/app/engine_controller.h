// The Engine on its own thread. The UI never calls the Engine: it posts commands that the worker
// runs between optimisation iterations, in order, and receives frames, statistics, progress and
// errors as signals on the UI thread. While optimisation runs, the worker alternates one
// iteration at the current camera (Himmler & Günther 2026, §III-F "Navigation": the optimisation
// follows the camera, warm-started from the current mu) with a render; while the user drags the
// camera it renders low-resolution previews first and the full image once the camera rests.
// While ClearView is on (the Hotspot tool) the frames are ClearView's instead, and a hotspot that
// moves only composites (engine_controller_clearview.cpp).
#pragma once

#include <atomic>
#include <chrono>
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

#include <visopt/clearview.h>
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
  // A ClearView frame (EngineController::setClearView) and what its render did: whether it
  // extracted the layers or composited only, the extractions so far, the times.
  bool clearView = false;
  ClearViewStats clearViewStats;
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

  // ClearView (Krüger et al. 2006; the Hotspot tool): while set, every frame is
  // Engine::renderClearView with `settings` instead of the normal render, and the optimisation
  // waits (each iteration moves the context surfaces, so every frame would extract the layers
  // again). The frame's size replaces the settings' width and height (a camera drag renders
  // 1/previewFactor of it first, as the normal preview does) and setClearViewFocus's position
  // their focusPixel. A render the library refuses (Error: a layer the scene lacks, a value out of
  // range) is reported through clearViewFailed, and the normal render is shown instead.
  // nullopt: normal frames (and the optimisation) again.
  void setClearView(std::optional<ClearViewSettings> settings);
  std::optional<ClearViewSettings> clearView() const;
  // The hotspot's position as a fraction of the image (x right, y down, in [0, 1]; negative: the
  // image centre), so that it maps onto whatever size the frame has. Only the newest position is
  // rendered: one that the worker has not picked up yet is simply replaced.
  void setClearViewFocus(glm::vec2 fraction);

  // Waits until the worker has nothing left to do right now: no command queued, no frame owed
  // (tests and --screenshot). Returns false on timeout.
  bool waitIdle(int timeoutMs);
  // While the user drags, the optimisation follows on the coarsest multigrid level between
  // previews (Engine::followCamera; on by default), so that the openings move with the camera.
  void setFollowWhileDragging(bool on);
  bool followWhileDragging() const { return followWhileDragging_; }
  // Coarse iterations run while following since the controller started (tests, the probe).
  int followIterations() const { return followIterations_; }
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
  // The library's message for a ClearView frame it refused (no dialog: the Hotspot panel and
  // the status bar show it until a ClearView frame succeeds).
  void clearViewFailed(const QString& message);

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
  // One call of Engine::followCamera while the user drags; false when it did nothing.
  bool followStep(Engine& engine);
  bool followOnce(Engine& engine);  // followStep; an error stops the optimisation and is shown
  void renderFrame(Engine& engine, bool preview);
  // ClearView's frame when it is on: true when the frame is done (rendered, or refused before for
  // the same settings and nothing changed since); false: render the normal frame.
  bool renderClearViewFrame(Engine& engine, bool preview);
  void deliver(std::function<void()> onUiThread);  // queued to the UI thread
  // A rendered frame to the UI; `owedAt`: the owed-frame serial when its render started.
  void frameDone(const QImage& image, const FrameInfo& info, bool preview, uint64_t owedAt);

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
  bool frameOwed_ = false;  // something changed since the last full frame
  // Counts the changes that owe a frame: a full frame settles what was owed only when none came
  // while it rendered (one that did, an edit or a ClearView setting, gets a frame of its own).
  uint64_t owedSerial_ = 0;
  void oweFrameLocked() {
    frameOwed_ = true;
    ++owedSerial_;
  }
  // While the user holds the camera, what is owed is shown by one preview, not by a preview
  // after every other: the full frame waits for the release.
  uint64_t previewedSerial_ = 0;
  bool owedFrameLocked() const {
    return frameOwed_ && !(interacting_ && previewedSerial_ == owedSerial_);
  }
  bool previewShown_ = false;  // the last frame was a preview
  RenderSettings render_;
  int viewportWidth_ = 512, viewportHeight_ = 512;

  std::atomic<bool> running_{false};
  std::atomic<bool> cancel_{false};
  std::atomic<bool> converged_{false};
  std::atomic<bool> followWhileDragging_{true};
  std::atomic<int> followIterations_{0};
  // Calls of Engine::followCamera still to run for the current drag position (under mutex_):
  // renewed at every camera change of a drag, so that a pause in the drag converges on the
  // coarse level and then rests.
  int followCallsLeft_ = 0;
  // Worker-only: when the last follow call after a drag's preview ended.
  std::chrono::steady_clock::time_point lastFollowInDrag_{};
  bool restartPending_ = true;  // next optimisation step runs the multigrid schedule
  int itersSinceFrame_ = 0;
  // Worker-only: convergence while following the camera.
  FollowConvergence follow_;
  QElapsedTimer sinceFrame_;

  std::shared_ptr<const SceneSnapshot> snapshot_;

  // ClearView: the UI's settings and hotspot (under mutex_); the settings of the last refused
  // render (under mutex_; forgotten when the settings, the camera or the scene change); the
  // worker's image, reused from frame to frame.
  std::optional<ClearViewSettings> clearView_;
  glm::vec2 clearViewFocus_{-1.f, -1.f};
  std::optional<ClearViewSettings> clearViewRefused_;
  Image clearViewImage_;
};

}  // namespace visopt::ws

Q_DECLARE_METATYPE(visopt::ws::FrameInfo)
Q_DECLARE_METATYPE(visopt::IterationStats)
