#include "command_line_files.h"

#include <QFileInfo>

#include <visopt/context_surface.h>

namespace visopt::ws {

CommandLineFiles sortCommandLineFiles(const QStringList& paths) {
  CommandLineFiles files;
  QString scene;  // the first volume or session, for the message when another follows
  for (const QString& path : paths) {
    const QString suffix = QFileInfo(path).suffix().toLower();
    const bool isDir = QFileInfo(path).isDir();
    if (!isDir && (suffix == QLatin1String("ply") || suffix == QLatin1String("obj") ||
                   suffix == QLatin1String("off") || suffix == QLatin1String("stl"))) {
      files.surfaces << QString::fromStdString(SurfaceSource::mesh(path.toStdString()).format());
      continue;
    }
    if (!isDir && suffix == QLatin1String("vdb")) {
      files.surfaces << QString::fromStdString(SurfaceSource::vdb(path.toStdString()).format());
      continue;
    }
    if (!scene.isEmpty()) {
      files.error = QStringLiteral("%1: only one volume or session opens at a time (%2 is open)")
                        .arg(path, scene);
      return files;
    }
    scene = path;
    if (!isDir && (suffix == QLatin1String("visopt-session") || suffix == QLatin1String("json")))
      files.session = path;
    else
      files.volume = path;
  }
  return files;
}

void addSceneOptions(CommandLineFiles& files, const SceneOptions& options) {
  if (!files.error.isEmpty()) return;
  QString named = !files.volume.isEmpty() ? files.volume : files.session;
  auto add = [&](const QString& value, const QString& option, QString& into) {
    if (value.isEmpty() || !files.error.isEmpty()) return;
    if (!named.isEmpty()) {
      files.error = QStringLiteral(
                        "%1 %2: only one volume, session or scene opens at a time (%3 "
                        "is open)")
                        .arg(option, value, named);
      return;
    }
    named = value;
    into = value;
  };
  add(options.volume, QStringLiteral("--volume"), files.volume);
  add(options.session, QStringLiteral("--session"), files.session);
  add(options.scene, QStringLiteral("--scene"), files.scene);
}

}  // namespace visopt::ws
