// Session <-> JSON text of the current format version (older versions go through migrate()).
//
//   {"format": "visopt-session", "version": 5,
//    "data": {"builtin": "shepp-logan", "resolution": 64}          (or {"volume": REF})
//    "precision": "fp16", "transferFunction": {...}, "importance": {"kind": "curve", ...},
//    "contextSurfaces": [{"source": "mesh:...", "file": REF, ...}], "extinction": {...},
//    "levelSet": {...}, "camera": {...}, "light": {...}, "lens": {...}, "render": {...},
//    "frozen": true, "worldMask": {"dims": [..], "encoding": "bits-lsb+zstd+base64", ...},
//    "clearView": {"context": LAYER, "focus": LAYER, "deeperContexts": [LAYER, ...],
//                  "moreFoci": [LAYER, ...], "measure": "distance", "size": 12, ...}}
//   REF = {"absolute": "/data/ct.nii.gz", "relative": "../data/ct.nii.gz", "sha256": .., "bytes":
//   ..}
//   LAYER = {"kind": "iso", "isovalue": -400} | {"kind": "surface", "surface": 0}
//         | {"kind": "importance", "isovalue": 0.5}
// Settings sections hold only values that differ from the defaults and are left out when empty.
// "clearView" is there when the session has hotspot settings at all; its first two layers are
// always written (their default is the scene's: a context surface, the importance), the further
// ones when there are any, everything else only where it differs from ClearViewSettings{}.
#include <nlohmann/json.hpp>

#include "session/json_fields.h"
#include "session/mask_codec.h"
#include "session/session_migrate.h"
#include "session/settings_tables.h"
#include "visopt/clearview.h"
#include "visopt/error.h"
#include "visopt/session.h"

namespace visopt {

using nlohmann::json;
using session::OrderedJson;
using session::Where;

namespace {

constexpr const char* kFormat = "visopt-session";
constexpr const char* kMaskEncoding = "bits-lsb+zstd+base64";

OrderedJson referenceToJson(const DataReference& ref) {
  OrderedJson j = OrderedJson::object();
  if (!ref.absolutePath.empty()) j["absolute"] = ref.absolutePath;
  if (!ref.relativePath.empty()) j["relative"] = ref.relativePath;
  if (!ref.sha256.empty()) j["sha256"] = ref.sha256;
  j["bytes"] = ref.bytes;
  return j;
}

DataReference referenceFromJson(const json& j, const Where& where) {
  session::expectObject(j, where);
  DataReference ref;
  session::readOptional(j, "absolute", ref.absolutePath, where);
  session::readOptional(j, "relative", ref.relativePath, where);
  session::readOptional(j, "sha256", ref.sha256, where);
  if (auto it = j.find("bytes"); it != j.end()) {
    if (!it->is_number_unsigned()) where.key("bytes").fail("expected a non-negative integer");
    ref.bytes = it->get<uint64_t>();
  }
  if (ref.empty()) where.fail("names no file (no \"absolute\" or \"relative\" path)");
  return ref;
}

void putIfNotEmpty(OrderedJson& doc, const char* key, OrderedJson value) {
  if (!value.empty()) doc[key] = std::move(value);
}

OrderedJson maskToJson(const SessionMask& m) {
  size_t set = 0;
  for (uint8_t b : m.bits) set += size_t(__builtin_popcount(b));
  return {{"dims", {m.dims.x, m.dims.y, m.dims.z}},
          {"encoding", kMaskEncoding},
          {"voxelsSet", set},
          {"data", session::encodeMaskBits(m.bits)}};
}

SessionMask maskFromJson(const json& j, const Where& where) {
  session::expectObject(j, where);
  SessionMask m;
  auto dims = j.find("dims");
  if (dims == j.end() || !dims->is_array() || dims->size() != 3)
    where.key("dims").fail("expected 3 positive integers");
  for (int i = 0; i < 3; ++i) {
    session::readValue((*dims)[size_t(i)], m.dims[i], where.key("dims").index(size_t(i)));
    if (m.dims[i] <= 0 || m.dims[i] > 65536) where.key("dims").fail("expected 3 positive integers");
  }
  std::string encoding, data;
  session::readRequired(j, "encoding", encoding, where);
  if (encoding != kMaskEncoding)
    where.key("encoding").fail("unknown encoding \"" + encoding + "\"");
  session::readRequired(j, "data", data, where);
  m.bits =
      session::decodeMaskBits(data, (m.voxelCount() + 7) / 8, where.origin + ": " + where.path);
  if (auto it = j.find("voxelsSet"); it != j.end()) {
    size_t set = 0;
    for (uint8_t b : m.bits) set += size_t(__builtin_popcount(b));
    if (!it->is_number_unsigned() || it->get<uint64_t>() != set)
      where.key("voxelsSet").fail("does not match the mask's data (corrupt)");
  }
  return m;
}

// ---- ClearView ----

OrderedJson layerToJson(const ClearViewLayer& layer) {
  OrderedJson j = {{"kind", toString(layer.kind)}};
  if (layer.kind == ClearViewLayerKind::ContextSurface)
    j["surface"] = layer.surface;
  else
    j["isovalue"] = layer.isovalue;
  return j;
}

// Only the member the kind uses is read; the other keeps its default, so a layer compares equal
// to the one written.
ClearViewLayer layerFromJson(const json& j, const Where& where) {
  session::expectObject(j, where);
  std::string kind;
  session::readRequired(j, "kind", kind, where);
  ClearViewLayer layer;
  if (kind == toString(ClearViewLayerKind::Isosurface)) {
    layer.kind = ClearViewLayerKind::Isosurface;
    session::readRequired(j, "isovalue", layer.isovalue, where);
  } else if (kind == toString(ClearViewLayerKind::ContextSurface)) {
    layer.kind = ClearViewLayerKind::ContextSurface;
    session::readRequired(j, "surface", layer.surface, where);
    if (layer.surface < 0) where.key("surface").fail("must be a context-surface index >= 0");
  } else if (kind == toString(ClearViewLayerKind::Importance)) {
    layer.kind = ClearViewLayerKind::Importance;
    session::readRequired(j, "isovalue", layer.isovalue, where);
    if (!(layer.isovalue > 0.0 && layer.isovalue <= 1.0))
      where.key("isovalue").fail("an importance level must lie in (0, 1]");
  } else {
    where.key("kind").fail("expected \"iso\", \"surface\" or \"importance\"");
  }
  return layer;
}

// The enum value whose toString is `name`, or a failure naming the choices.
template <class E, size_t N>
E enumFromJson(const json& j, const E (&values)[N], const Where& where) {
  std::string name;
  session::readValue(j, name, where);
  std::string choices;
  for (E v : values) {
    if (name == toString(v)) return v;
    choices += (choices.empty() ? "\"" : ", \"") + std::string(toString(v)) + "\"";
  }
  where.fail("unknown \"" + name + "\" (expected " + choices + ")");
}

constexpr ClearViewMeasure kMeasures[] = {ClearViewMeasure::Curvature, ClearViewMeasure::Distance,
                                          ClearViewMeasure::ViewDistance};
constexpr ClearViewShader kShaders[] = {ClearViewShader::Diffuse, ClearViewShader::CoolWarm,
                                        ClearViewShader::Skin, ClearViewShader::Bone};

OrderedJson clearViewToJson(const ClearViewSettings& c) {
  const ClearViewSettings defaults;
  OrderedJson j = {{"context", layerToJson(c.context)}, {"focus", layerToJson(c.focus)}};
  for (const auto& [key, layers] : {std::pair<const char*, const std::vector<ClearViewLayer>*>{
                                        "deeperContexts", &c.deeperContexts},
                                    {"moreFoci", &c.moreFoci}}) {
    if (layers->empty()) continue;
    OrderedJson list = OrderedJson::array();
    for (const ClearViewLayer& l : *layers) list.push_back(layerToJson(l));
    j[key] = list;
  }
  if (c.measure != defaults.measure) j["measure"] = toString(c.measure);
  if (c.contextShader != defaults.contextShader) j["contextShader"] = toString(c.contextShader);
  if (c.focusShader != defaults.focusShader) j["focusShader"] = toString(c.focusShader);
  j.update(session::clearViewFields().write(c));
  return j;
}

ClearViewSettings clearViewFromJson(const json& j, const Where& where) {
  session::expectObject(j, where);
  ClearViewSettings c;
  auto layer = [&](const char* key) {
    auto it = j.find(key);
    if (it == j.end()) where.fail(std::string("missing \"") + key + "\" (its layer)");
    return layerFromJson(*it, where.key(key));
  };
  c.context = layer("context");
  c.focus = layer("focus");
  for (const auto& [key, layers] :
       {std::pair<const char*, std::vector<ClearViewLayer>*>{"deeperContexts", &c.deeperContexts},
        {"moreFoci", &c.moreFoci}}) {
    auto it = j.find(key);
    if (it == j.end()) continue;
    const Where at = where.key(key);
    if (!it->is_array()) at.fail("must be a list of layers");
    if (it->size() >= size_t(kClearViewMaxLayers))
      at.fail("at most " + std::to_string(kClearViewMaxLayers - 1) + " layers");
    for (size_t i = 0; i < it->size(); ++i) layers->push_back(layerFromJson((*it)[i], at.index(i)));
  }
  if (auto it = j.find("measure"); it != j.end())
    c.measure = enumFromJson(*it, kMeasures, where.key("measure"));
  if (auto it = j.find("contextShader"); it != j.end())
    c.contextShader = enumFromJson(*it, kShaders, where.key("contextShader"));
  if (auto it = j.find("focusShader"); it != j.end())
    c.focusShader = enumFromJson(*it, kShaders, where.key("focusShader"));
  session::clearViewFields().read(j, c, where);
  if (!(c.size >= 0.f)) where.key("size").fail("must be >= 0 (world units; 0: automatic)");
  if (!(c.weight >= 0.f)) where.key("weight").fail("must be >= 0");
  if (!(c.distanceScale >= 0.f))
    where.key("distanceScale").fail("must be >= 0 (world units; 0: the size)");
  if (!(c.ambient >= 0.f && c.ambient <= 1.f)) where.key("ambient").fail("must lie in [0, 1]");
  for (const auto& [key, colour] :
       {std::pair<const char*, glm::vec3>{"contextColor", c.contextColor},
        {"focusColor", c.focusColor},
        {"background", c.background}})
    if (!(colour.r >= 0.f && colour.g >= 0.f && colour.b >= 0.f))
      where.key(key).fail("colour components must be >= 0 (linear RGB)");
  // Whatever else the library checks (the same rules; a net for rules added there later).
  try {
    checkClearViewSettings(c);
  } catch (const Error& e) {
    std::string problem = e.what();
    const std::string prefix = "ClearView: ";  // the library's own prefix
    if (problem.rfind(prefix, 0) == 0) problem.erase(0, prefix.size());
    where.fail(problem);
  }
  return c;
}

// Everything a version-current document holds, read into `s`.
void readCurrent(const json& doc, Session& s, const Where& top) {
  // Data source.
  {
    auto it = doc.find("data");
    if (it == doc.end()) top.fail("missing \"data\" (the volume or built-in scene)");
    const Where w = top.key("data");
    session::expectObject(*it, w);
    if (it->contains("builtin")) {
      session::readRequired(*it, "builtin", s.builtinScene, w);
      if (s.builtinScene.empty()) w.key("builtin").fail("empty scene name");
      session::readOptional(*it, "resolution", s.builtinResolution, w);
      if (s.builtinResolution < 2) w.key("resolution").fail("must be at least 2");
    } else if (auto v = it->find("volume"); v != it->end()) {
      s.volume = referenceFromJson(*v, w.key("volume"));
    } else {
      w.fail("expected \"builtin\" or \"volume\"");
    }
  }
  if (auto it = doc.find("precision"); it != doc.end()) {
    std::string p;
    session::readValue(*it, p, top.key("precision"));
    if (p != "fp32" && p != "fp16") top.key("precision").fail("expected \"fp32\" or \"fp16\"");
    s.precision = p == "fp16" ? Precision::FP16 : Precision::FP32;
  }
  if (auto it = doc.find("transferFunction"); it != doc.end()) {
    session::expectObject(*it, top.key("transferFunction"));
    s.transferFunction = TransferFunction::fromJson(it->dump(), top.origin + ": transferFunction");
  }
  if (auto it = doc.find("importance"); it != doc.end()) {
    const Where w = top.key("importance");
    session::expectObject(*it, w);
    std::string kind;
    session::readRequired(*it, "kind", kind, w);
    if (kind == "scene") {
      s.importance.kind = SessionImportance::Kind::Scene;
    } else if (kind == "curve") {
      s.importance.kind = SessionImportance::Kind::Curve;
      auto points = it->find("points");
      if (points == it->end()) w.fail("missing \"points\"");
      session::expectArray(*points, w.key("points"));
      for (size_t i = 0; i < points->size(); ++i) {
        glm::dvec2 p;
        session::readValue((*points)[i], p, w.key("points").index(i));
        s.importance.curve.push_back(p);
      }
    } else if (kind == "volume") {
      s.importance.kind = SessionImportance::Kind::Volume;
      auto file = it->find("file");
      if (file == it->end()) w.fail("missing \"file\"");
      s.importance.volume = referenceFromJson(*file, w.key("file"));
    } else if (kind == "hotspot") {
      s.importance.kind = SessionImportance::Kind::Hotspot;
      session::readRequired(*it, "centre", s.importance.hotspotCentre, w);
      session::readRequired(*it, "radius", s.importance.hotspotRadius, w);
      if (!(s.importance.hotspotRadius > 0.f))
        w.key("radius").fail("must be positive (world units)");
    } else if (kind != "none") {
      w.key("kind").fail("expected \"scene\", \"curve\", \"volume\" or \"hotspot\"");
    }
  }
  if (auto it = doc.find("contextSurfaces"); it != doc.end()) {
    const Where w = top.key("contextSurfaces");
    session::expectArray(*it, w);
    for (size_t i = 0; i < it->size(); ++i) {
      const json& sj = (*it)[i];
      const Where ws = w.index(i);
      SessionSurface surface;
      session::surfaceFields().read(sj, surface.spec, ws);
      session::readRequired(sj, "source", surface.spec.source, ws);
      if (auto f = sj.find("file"); f != sj.end())
        surface.file = referenceFromJson(*f, ws.key("file"));
      s.contextSurfaces.push_back(std::move(surface));
    }
  }
  if (auto it = doc.find("extinction"); it != doc.end()) {
    session::extinctionFields().read(*it, s.extinction, top.key("extinction"));
    if (auto o = it->find("optimizer"); o != it->end()) {
      std::string name;
      session::readValue(*o, name, top.key("extinction").key("optimizer"));
      try {
        s.extinction.optimizer = parseOptimizerKind(name);
      } catch (const Error&) {
        top.key("extinction").key("optimizer").fail("unknown optimizer \"" + name + "\"");
      }
    }
  }
  if (auto it = doc.find("levelSet"); it != doc.end())
    session::levelSetFields().read(*it, s.levelSet, top.key("levelSet"));
  if (auto it = doc.find("camera"); it != doc.end()) {
    Camera c;
    session::cameraFields().read(*it, c, top.key("camera"));
    s.camera = c;
  }
  if (auto it = doc.find("light"); it != doc.end()) {
    PointLight l;
    session::lightFields().read(*it, l, top.key("light"));
    s.light = l;
  }
  if (auto it = doc.find("lens"); it != doc.end())
    session::lensFields().read(*it, s.lens, top.key("lens"));
  if (auto it = doc.find("render"); it != doc.end()) {
    session::renderFields().read(*it, s.render, top.key("render"));
    if (auto c = it->find("deviationColormap"); c != it->end()) {
      std::string name;
      session::readValue(*c, name, top.key("render").key("deviationColormap"));
      try {
        s.render.deviationColormap = parseColormap(name);
      } catch (const Error&) {
        top.key("render").key("deviationColormap").fail("unknown colormap \"" + name + "\"");
      }
    }
  }
  session::readOptional(doc, "frozen", s.frozen, top);
  if (auto it = doc.find("worldMask"); it != doc.end())
    s.worldMask = maskFromJson(*it, top.key("worldMask"));
  if (auto it = doc.find("clearView"); it != doc.end())
    s.clearView = clearViewFromJson(*it, top.key("clearView"));
}

std::string oneLine(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  return text;
}

}  // namespace

std::string sessionToJson(const Session& s, const std::string& sessionPath) {
  OrderedJson doc = {{"format", kFormat}, {"version", kSessionFormatVersion}};
  if (!s.builtinScene.empty())
    doc["data"] = {{"builtin", s.builtinScene}, {"resolution", s.builtinResolution}};
  else
    doc["data"] = {{"volume", referenceToJson(rebaseDataReference(s.volume, sessionPath))}};
  if (s.precision != Precision::FP32) doc["precision"] = toString(s.precision);
  if (s.transferFunction)
    doc["transferFunction"] = OrderedJson::parse(s.transferFunction->toJson());
  if (s.importance.kind != SessionImportance::Kind::None) {
    OrderedJson imp = {{"kind", toString(s.importance.kind)}};
    if (s.importance.kind == SessionImportance::Kind::Curve) {
      OrderedJson points = OrderedJson::array();
      for (const auto& p : s.importance.curve) points.push_back({p.x, p.y});
      imp["points"] = std::move(points);
    } else if (s.importance.kind == SessionImportance::Kind::Volume) {
      imp["file"] = referenceToJson(rebaseDataReference(s.importance.volume, sessionPath));
    } else if (s.importance.kind == SessionImportance::Kind::Hotspot) {
      imp["centre"] = session::toJson(s.importance.hotspotCentre);
      imp["radius"] = session::toJson(s.importance.hotspotRadius);
    }
    doc["importance"] = std::move(imp);
  }
  if (!s.contextSurfaces.empty()) {
    OrderedJson list = OrderedJson::array();
    for (const SessionSurface& surface : s.contextSurfaces) {
      OrderedJson sj = {{"source", surface.spec.source}};
      sj.update(session::surfaceFields().write(surface.spec));
      if (!surface.file.empty())
        sj["file"] = referenceToJson(rebaseDataReference(surface.file, sessionPath));
      list.push_back(std::move(sj));
    }
    doc["contextSurfaces"] = std::move(list);
  }
  {
    OrderedJson ext = session::extinctionFields().write(s.extinction);
    if (s.extinction.optimizer != ExtinctionSettings{}.optimizer)
      ext["optimizer"] = toString(s.extinction.optimizer);
    putIfNotEmpty(doc, "extinction", std::move(ext));
  }
  putIfNotEmpty(doc, "levelSet", session::levelSetFields().write(s.levelSet));
  if (s.camera) doc["camera"] = session::cameraFields().writeAll(*s.camera);
  if (s.light) doc["light"] = session::lightFields().writeAll(*s.light);
  putIfNotEmpty(doc, "lens", session::lensFields().write(s.lens));
  {
    OrderedJson render = session::renderFields().write(s.render);
    if (s.render.deviationColormap != RenderSettings{}.deviationColormap)
      render["deviationColormap"] = toString(s.render.deviationColormap);
    putIfNotEmpty(doc, "render", std::move(render));
  }
  if (s.frozen) doc["frozen"] = true;
  if (s.worldMask) doc["worldMask"] = maskToJson(*s.worldMask);
  if (s.clearView) doc["clearView"] = clearViewToJson(*s.clearView);
  return doc.dump(2) + "\n";
}

Session sessionFromJson(const std::string& text, const std::string& origin) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // parse errors, and numbers beyond double (1e999)
    std::string msg = e.what();
    if (auto close = msg.find("] ");
        !msg.empty() && msg.front() == '[' && close != std::string::npos)
      msg = msg.substr(close + 2);
    throwBadInput(origin, "not a session file: invalid JSON (" + oneLine(msg) + ")");
  }
  const Where top{origin, {}};
  if (!doc.is_object()) top.fail("not a session file: expected a JSON object");
  auto format = doc.find("format");
  if (format == doc.end() || !format->is_string() || format->get<std::string>() != kFormat)
    top.fail(std::string("not a session file: \"format\" is not \"") + kFormat + "\"");
  int version = 0;
  session::readRequired(doc, "version", version, top);
  if (version < 1) top.key("version").fail("must be at least 1");
  if (version > kSessionFormatVersion)
    top.fail("session format version " + std::to_string(version) +
             " is newer than this visopt reads (" + std::to_string(kSessionFormatVersion) + ")");
  try {
    session::migrate(doc, version, top);
    Session s;
    s.version = version;
    readCurrent(doc, s, top);
    return s;
  } catch (const json::exception& e) {  // a structure no check above foresaw
    top.fail("malformed session: " + oneLine(e.what()));
  }
}

const char* toString(SessionImportance::Kind kind) {
  switch (kind) {
    case SessionImportance::Kind::Scene:
      return "scene";
    case SessionImportance::Kind::Curve:
      return "curve";
    case SessionImportance::Kind::Volume:
      return "volume";
    case SessionImportance::Kind::Hotspot:
      return "hotspot";
    case SessionImportance::Kind::None:
      break;
  }
  return "none";
}

}  // namespace visopt
