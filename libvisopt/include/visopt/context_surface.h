// What a context surface is made of, as a user states it.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "visopt/grid.h"

namespace visopt {

// A context surface (Himmler & Günther 2026, §III): opaque geometry held as an SDF on the volume's
// grid.
struct ContextSurfaceSpec {
  // "iso:VALUE[:inside-high|inside-low]" (an isosurface of the data; inside-high: values above
  // VALUE are inside, the default), "mesh:FILE" (OBJ/PLY/OFF/STL) or "vdb:FILE".
  std::string source;
  bool filled = true;
  float shell = 0.f;  // d of Eq. 26 in world units when !filled: the shell reaches d each side
  glm::vec3 color{0.87f, 0.72f, 0.6f};
  bool visible = true;
};

// A context surface's source, typed, and its text form as ContextSurfaceSpec::source, sessions
// and the CLI's --context write it: "iso:VALUE[:inside-high|inside-low]" (an isosurface of the
// data; inside-high, the default: values above VALUE are inside), "mesh:FILE" or "vdb:FILE".
struct SurfaceSource {
  enum class Kind { Iso, Mesh, Vdb };
  Kind kind = Kind::Iso;
  double isoValue = 0.0;   // Iso
  bool insideHigh = true;  // Iso
  std::string file;        // Mesh, Vdb

  static SurfaceSource iso(double value, bool insideHigh = true);
  static SurfaceSource mesh(std::string file);
  static SurfaceSource vdb(std::string file);
  // Throws Error(Usage) naming `text` unless it is one of the forms above, with a finite VALUE
  // and a FILE that is not empty (everything after the first colon: a path may hold colons).
  static SurfaceSource parse(const std::string& text);
  // The text form; VALUE in the shortest form that reads back as the same double.
  std::string format() const;
  bool hasFile() const { return kind != Kind::Iso; }
  bool operator==(const SurfaceSource&) const = default;
};

// The representation a source gets unless the user chooses: an isosurface of the data
// ("iso:...") is a thin shell reaching one voxel (the grid's smallest spacing) each side, since
// the isosurface of a scan bounds a tissue layer (skin, a vessel wall), not a solid: filled, a
// skin hides everything inside the head, and Eq. 23 can open it at best down to a minimal
// surface spanning the rim of what lies behind, so the far half of an important structure
// inside stays hidden (README, "Context surfaces that give way"). Meshes and .vdb files stay
// filled, as their authors closed them.
ContextSurfaceSpec defaultContextSurfaceSpec(const std::string& source, const GridSpec& grid);

}  // namespace visopt
