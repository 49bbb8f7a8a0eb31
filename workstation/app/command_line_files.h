// The files named on visopt-workstation's command line, sorted by what they open: one scene
// (a volume file or DICOM folder, or a session) and any number of context surfaces (meshes and
// OpenVDB level sets), as a user of ParaView or Slicer expects `app FILE...` to do.
#pragma once

#include <QString>
#include <QStringList>

namespace visopt::ws {

struct CommandLineFiles {
  QString volume;        // a volume file or a DICOM folder
  QString session;       // a .visopt-session (or .json) session
  QString scene;         // a built-in scene, "builtin:NAME" (from --scene only)
  QStringList surfaces;  // context-surface sources: "mesh:FILE" or "vdb:FILE"
  QString error;         // non-empty: the files cannot be opened together (one line)
};

// Sorts by name: .visopt-session and .json are sessions; .ply, .obj, .off and .stl meshes and
// .vdb level sets become context surfaces; anything else (a folder, .nii, .mhd, .vti, .raw, ...)
// is a volume, which the readers identify. At most one volume or session.
CommandLineFiles sortCommandLineFiles(const QStringList& paths);

// The scene options given besides the files (empty: not given).
struct SceneOptions {
  QString volume;   // --volume
  QString session;  // --session
  QString scene;    // --scene
};

// Adds the options' scene to `files`: an error (one line naming both) when the files and the
// options together name more than one volume, session or built-in scene, instead of opening
// one of them silently.
void addSceneOptions(CommandLineFiles& files, const SceneOptions& options);

}  // namespace visopt::ws
