// Where the workstation keeps its own files: the autosave, the crash marker that tells the next
// start to offer recovery, and the recent-sessions list. A state folder can be given (tests use
// a temporary one); the default is the platform's application-data folder.
#pragma once

#include <QString>
#include <QStringList>

namespace visopt::ws {

class SessionFiles {
 public:
  explicit SessionFiles(QString stateDir = {});

  const QString& stateDir() const { return dir_; }
  QString autosavePath() const;
  QString layoutPath() const;  // the window's panel arrangement (QMainWindow::saveState)
  // The marker exists while the application runs; a marker found at start means the last run
  // ended without a clean exit (a crash), so its autosave is offered for recovery.
  QString runningMarkerPath() const;
  // A marker of a process that is gone and an autosave next to it, as found when markRunning()
  // was called (or now, before that).
  bool previousRunCrashed() const;
  void markRunning();
  void markCleanExit();  // removes the marker and the autosave

  QStringList recentSessions() const;
  void addRecentSession(const QString& path);  // most recent first, at most 10, no duplicates

 private:
  bool crashEvidence() const;
  QString dir_;
  bool markedRunning_ = false;
  bool crashedBefore_ = false;
};

}  // namespace visopt::ws
