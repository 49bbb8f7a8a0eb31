// SurfaceSource (visopt/context_surface.h): the one parser and formatter of a context surface's
// source text.
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "visopt/context_surface.h"
#include "visopt/error.h"

namespace visopt {

namespace {

Error malformed(const std::string& text, const std::string& what) {
  return Error(ErrorKind::Usage, "context '" + text + "': " + what);
}

bool startsWith(const std::string& s, const char* prefix) {
  return s.rfind(prefix, 0) == 0;
}

}  // namespace

SurfaceSource SurfaceSource::iso(double value, bool insideHigh) {
  SurfaceSource s;
  s.kind = Kind::Iso;
  s.isoValue = value;
  s.insideHigh = insideHigh;
  return s;
}

SurfaceSource SurfaceSource::mesh(std::string file) {
  SurfaceSource s;
  s.kind = Kind::Mesh;
  s.file = std::move(file);
  return s;
}

SurfaceSource SurfaceSource::vdb(std::string file) {
  SurfaceSource s;
  s.kind = Kind::Vdb;
  s.file = std::move(file);
  return s;
}

SurfaceSource SurfaceSource::parse(const std::string& text) {
  for (const auto& [prefix, kind] : {std::pair{"mesh:", Kind::Mesh}, std::pair{"vdb:", Kind::Vdb}})
    if (startsWith(text, prefix)) {
      std::string file = text.substr(std::string(prefix).size());
      if (file.empty()) throw malformed(text, "no file after the colon");
      return kind == Kind::Mesh ? mesh(std::move(file)) : vdb(std::move(file));
    }
  if (!startsWith(text, "iso:"))
    throw malformed(text, "expected iso:VALUE[:inside-high|inside-low], mesh:FILE or vdb:FILE");
  std::string value = text.substr(4);
  bool insideHigh = true;
  if (const auto colon = value.find(':'); colon != std::string::npos) {
    const std::string side = value.substr(colon + 1);
    if (side == "inside-high")
      insideHigh = true;
    else if (side == "inside-low")
      insideHigh = false;
    else
      throw malformed(text, "expected inside-high or inside-low");
    value.resize(colon);
  }
  double v = 0.0;
  try {
    size_t used = 0;
    v = std::stod(value, &used);
    if (used != value.size()) throw std::invalid_argument(value);
  } catch (const std::exception&) {
    throw malformed(text, "VALUE must be a number");
  }
  if (!std::isfinite(v)) throw malformed(text, "VALUE must be a finite number");
  return iso(v, insideHigh);
}

std::string SurfaceSource::format() const {
  switch (kind) {
    case Kind::Mesh:
      return "mesh:" + file;
    case Kind::Vdb:
      return "vdb:" + file;
    case Kind::Iso:
      break;
  }
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), isoValue);
  return "iso:" + std::string(buffer, result.ptr) + (insideHigh ? ":inside-high" : ":inside-low");
}

}  // namespace visopt
