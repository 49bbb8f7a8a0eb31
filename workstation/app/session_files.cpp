#include "session_files.h"

#include <QCoreApplication>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QSaveFile>
#include <QStandardPaths>
#include <QTextStream>

namespace visopt::ws {

namespace {
constexpr int kMaxRecent = 10;
}

SessionFiles::SessionFiles(QString stateDir) : dir_(std::move(stateDir)) {
  if (dir_.isEmpty()) dir_ = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation);
  if (dir_.isEmpty()) dir_ = QDir::homePath() + QStringLiteral("/.visopt");
  QDir().mkpath(dir_);
}

QString SessionFiles::autosavePath() const {
  return dir_ + QStringLiteral("/autosave.visopt-session");
}

QString SessionFiles::layoutPath() const {
  return dir_ + QStringLiteral("/window-layout.bin");
}

QString SessionFiles::runningMarkerPath() const {
  return dir_ + QStringLiteral("/running.marker");
}

bool SessionFiles::previousRunCrashed() const {
  return markedRunning_ ? crashedBefore_ : crashEvidence();
}

bool SessionFiles::crashEvidence() const {
  if (!QFileInfo::exists(runningMarkerPath()) || !QFileInfo::exists(autosavePath())) return false;
  // A marker of a process that still runs is another instance at work, not a crash.
  QFile marker(runningMarkerPath());
  if (!marker.open(QIODevice::ReadOnly)) return true;
  const qint64 pid = marker.readAll().trimmed().toLongLong();
  if (pid <= 0 || pid == QCoreApplication::applicationPid()) return true;
  return !QFileInfo::exists(QStringLiteral("/proc/%1").arg(pid));
}

void SessionFiles::markRunning() {
  crashedBefore_ = crashEvidence();  // decided before this run's marker replaces the old one
  markedRunning_ = true;
  QFile marker(runningMarkerPath());
  if (marker.open(QIODevice::WriteOnly | QIODevice::Truncate))
    marker.write(QByteArray::number(QCoreApplication::applicationPid()));
}

void SessionFiles::markCleanExit() {
  QFile::remove(autosavePath());
  QFile::remove(runningMarkerPath());
}

QStringList SessionFiles::recentSessions() const {
  QFile f(dir_ + QStringLiteral("/recent-sessions.txt"));
  QStringList out;
  if (!f.open(QIODevice::ReadOnly)) return out;
  QTextStream in(&f);
  while (!in.atEnd()) {
    const QString line = in.readLine().trimmed();
    if (!line.isEmpty() && !out.contains(line)) out << line;
  }
  return out.mid(0, kMaxRecent);
}

void SessionFiles::addRecentSession(const QString& path) {
  QStringList list = recentSessions();
  const QString abs = QFileInfo(path).absoluteFilePath();
  list.removeAll(abs);
  list.prepend(abs);
  QSaveFile f(dir_ + QStringLiteral("/recent-sessions.txt"));
  if (!f.open(QIODevice::WriteOnly)) return;
  QTextStream out(&f);
  for (const QString& p : list.mid(0, kMaxRecent)) out << p << '\n';
  out.flush();
  f.commit();
}

}  // namespace visopt::ws
