// Mesh loading (OpenMesh) and repair. OpenMesh's readers are forgiving: an ASCII OFF file that
// ends early or holds "nan" loads as a partial mesh, a face with a repeated vertex is dropped
// with a message on OpenMesh's error stream, and a face that would make an edge non-manifold is
// added on copies of its vertices. So this file validates what OpenMesh cannot (OFF structure,
// binary STL size, PLY element counts), captures OpenMesh's error stream, and then repairs and
// checks the triangle list itself.
#include "sdf/mesh_loading.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <streambuf>
#include <unordered_map>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include "io/file_util.h"
#include "visopt/error.h"

namespace visopt::sdf {

void reportProgress(const ProgressCallback& progress, const std::string& path, float fraction,
                    const std::string& stage) {
  if (progress && !progress(std::clamp(fraction, 0.f, 1.f), stage))
    throw Error(ErrorKind::Cancelled, path + ": cancelled");
}

namespace {

using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

// OpenMesh reports through process-wide streams; loads are serialised while they are redirected.
std::mutex& openMeshStreamMutex() {
  static std::mutex mutex;
  return mutex;
}

// Routes OpenMesh's error stream into a string (and silences its log) for one load.
class OpenMeshErrorCapture {
 public:
  OpenMeshErrorCapture() {
    reconnectCerr_ = omerr().disconnect(std::cerr);
    omerr().connect(text_);
    logWasEnabled_ = omlog().is_enabled();
    omlog().disable();
  }
  ~OpenMeshErrorCapture() {
    omerr() << std::flush;
    omerr().disconnect(text_);
    if (reconnectCerr_) omerr().connect(std::cerr);
    if (logWasEnabled_) omlog().enable();
  }
  OpenMeshErrorCapture(const OpenMeshErrorCapture&) = delete;
  OpenMeshErrorCapture& operator=(const OpenMeshErrorCapture&) = delete;

  std::string text() {
    omerr() << std::flush;
    return text_.str();
  }

 private:
  std::ostringstream text_;
  bool reconnectCerr_ = false, logWasEnabled_ = false;
};

size_t countOccurrences(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string firstLine(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Next line that holds something other than blanks and a '#' comment; false at the end.
bool nextContentLine(std::istringstream& in, std::string& line, size_t& lineNumber) {
  while (std::getline(in, line)) {
    ++lineNumber;
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    if (line.find_first_not_of(" \t\r") != std::string::npos) return true;
  }
  return false;
}

// Structure check of a plain ASCII "OFF" file: counts, vertex lines with three finite numbers,
// faces whose indices exist. Variants (COFF, NOFF, binary OFF, ...) are left to OpenMesh.
void validateAsciiOff(const std::string& path) {
  std::istringstream in(readWholeFile(path));
  std::string line;
  size_t lineNumber = 0;
  if (!nextContentLine(in, line, lineNumber)) throwBadInput(path, "no OFF header");
  std::istringstream header(line);
  std::string magic;
  header >> magic;
  if (magic != "OFF") return;
  long long counts[3] = {-1, -1, 0};
  if (!(header >> counts[0])) {
    if (!nextContentLine(in, line, lineNumber))
      throwBadInput(path, "truncated: the OFF header has no vertex and face counts");
    std::istringstream countLine(line);
    if (!(countLine >> counts[0] >> counts[1]))
      throwBadInput(path,
                    "line " + std::to_string(lineNumber) + ": expected the vertex and face counts");
  } else if (!(header >> counts[1])) {
    throwBadInput(path, "line " + std::to_string(lineNumber) + ": expected the face count");
  }
  const long long nv = counts[0], nf = counts[1];
  if (nv <= 0 || nf <= 0)
    throwBadInput(path, "the OFF header declares " + std::to_string(nv) + " vertices and " +
                            std::to_string(nf) + " faces");
  for (long long v = 0; v < nv; ++v) {
    if (!nextContentLine(in, line, lineNumber))
      throwBadInput(path,
                    "truncated: " + std::to_string(v) + " of " + std::to_string(nv) + " vertices");
    const char* at = line.c_str();
    for (int c = 0; c < 3; ++c) {
      char* end = nullptr;
      const float x = std::strtof(at, &end);
      if (end == at)
        throwBadInput(path, "line " + std::to_string(lineNumber) + ": expected a vertex (x y z)");
      if (!std::isfinite(x))
        throwBadInput(path, "vertex " + std::to_string(v) + " (line " + std::to_string(lineNumber) +
                                ") has a NaN or infinite coordinate");
      at = end;
    }
  }
  for (long long f = 0; f < nf; ++f) {
    if (!nextContentLine(in, line, lineNumber))
      throwBadInput(path,
                    "truncated: " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    std::istringstream face(line);
    long long n = 0;
    if (!(face >> n) || n < 3)
      throwBadInput(path, "line " + std::to_string(lineNumber) + ": expected a face (n i1 .. in)");
    for (long long k = 0; k < n; ++k) {
      long long index = -1;
      if (!(face >> index))
        throwBadInput(path, "line " + std::to_string(lineNumber) + ": face with fewer than " +
                                std::to_string(n) + " vertex indices");
      if (index < 0 || index >= nv)
        throwBadInput(path, "line " + std::to_string(lineNumber) + ": face refers to vertex " +
                                std::to_string(index) + " of " + std::to_string(nv));
    }
  }
}

// A binary STL's size is fixed by its triangle count; OpenMesh reads a short one as ASCII.
void validateStl(const std::string& path, uint64_t size) {
  std::ifstream in(path, std::ios::binary);
  char head[84] = {};
  in.read(head, sizeof head);
  const bool asciiStart = size >= 5 && std::strncmp(head, "solid", 5) == 0;
  if (size < 84) {
    if (!asciiStart) throwBadInput(path, "truncated: shorter than a binary STL header");
    return;
  }
  uint32_t count = 0;
  std::memcpy(&count, head + 80, sizeof count);
  if (io::hostIsBigEndian()) io::swapBytesInPlace(&count, 1, sizeof count);
  const uint64_t expected = 84 + 50 * uint64_t(count);
  if (expected == size) {
    // OpenMesh merges STL corners in an ordered map, which a NaN corrupts: check first.
    char record[50];
    for (uint32_t t = 0; t < count && in.read(record, sizeof record); ++t) {
      float corner[9];
      std::memcpy(corner, record + 12, sizeof corner);
      if (io::hostIsBigEndian()) io::swapBytesInPlace(corner, 9, sizeof(float));
      for (float x : corner)
        if (!std::isfinite(x))
          throwBadInput(path, "triangle " + std::to_string(t) + " has a NaN or infinite vertex");
    }
    return;
  }
  if (asciiStart) return;
  throwBadInput(path, "truncated or malformed binary STL: " + std::to_string(count) +
                          " triangles need " + std::to_string(expected) + " bytes, the file has " +
                          std::to_string(size));
}

// The PLY header, checked line by line before OpenMesh parses it: OpenMesh's reader looped
// without end on a header without "end_header" and crashed on malformed element or property
// lines (mutants of a valid file, issue 13). Accepted: "ply", a format line (ascii or binary,
// version 1.0), comment/obj_info lines, "element NAME COUNT" and "property [list T] T NAME"
// with PLY's scalar types, then "end_header" within the first 1000 lines; a vertex element with
// x, y and z and a face element with a vertex_indices list; counts the file's bytes can hold.
void validatePlyHeader(const std::string& path, uint64_t size) {
  static const char* const scalarTypes[] = {
      "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
      "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  auto isScalar = [](const std::string& t) {
    for (const char* s : scalarTypes)
      if (t == s) return true;
    return false;
  };
  // A header line for a one-line message: at most 60 characters, non-printable bytes as '?'.
  auto shown = [](const std::string& text) {
    std::string out = text.substr(0, 60);
    for (char& ch : out)
      if (static_cast<unsigned char>(ch) < 32 || static_cast<unsigned char>(ch) > 126) ch = '?';
    return out;
  };
  std::ifstream in(path, std::ios::binary);
  std::string line;
  auto next = [&]() {
    if (!std::getline(in, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next() || line != "ply") throwBadInput(path, "not a PLY file (no \"ply\" line)");
  if (!next() || (line != "format ascii 1.0" && line != "format binary_little_endian 1.0" &&
                  line != "format binary_big_endian 1.0"))
    throwBadInput(
        path, "malformed PLY header: expected a format line, got \"" + line.substr(0, 60) + "\"");
  std::string element;
  long long vertices = -1, faces = -1;
  bool x = false, y = false, z = false, indices = false, ended = false;
  for (int n = 0; n < 1000 && next(); ++n) {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "end_header") {
      ended = true;
      break;
    }
    if (word == "comment" || word == "obj_info") continue;
    auto bad = [&] {
      throwBadInput(
          path, "malformed PLY header line " + std::to_string(n + 3) + ": \"" + shown(line) + "\"");
    };
    std::string a, b, c, rest;
    if (word == "element") {
      long long count = -1;
      if (!(words >> element >> count) || (words >> rest) || count < 0) bad();
      // Every element takes at least a byte per entry (ascii: a digit and a separator).
      if (uint64_t(count) > size) bad();
      if (element == "vertex") vertices = count;
      if (element == "face") faces = count;
    } else if (word == "property") {
      if (element.empty() || !(words >> a)) bad();
      if (a == "list") {
        if (!(words >> b >> c >> rest) || !isScalar(b) || !isScalar(c) || b == "float" ||
            b == "double" || b == "float32" || b == "float64")
          bad();
        if (element == "face" && (rest == "vertex_indices" || rest == "vertex_index"))
          indices = true;
      } else {
        if (!isScalar(a) || !(words >> b) || (words >> rest)) bad();
        if (element == "vertex") {
          x = x || b == "x";
          y = y || b == "y";
          z = z || b == "z";
        }
      }
    } else {
      bad();
    }
  }
  if (!ended) throwBadInput(path, "malformed or truncated PLY header: no end_header line");
  if (vertices < 0 || !(x && y && z))
    throwBadInput(path, "the PLY file has no vertex element with x, y and z");
  if (faces < 0 || !indices)
    throwBadInput(path, "the PLY file has no face element with a vertex_indices list");
}

// "element vertex N" / "element face M" from a PLY header (-1 when absent).
void plyCounts(const std::string& path, long long& vertices, long long& faces) {
  vertices = faces = -1;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int n = 0; n < 1000 && std::getline(in, line); ++n) {
    std::istringstream s(line);
    std::string word, element;
    long long count = -1;
    s >> word;
    if (word == "end_header") break;
    if (word == "element" && (s >> element >> count)) {
      if (element == "vertex") vertices = count;
      if (element == "face") faces = count;
    }
  }
}

struct CellKey {
  int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  size_t operator()(const CellKey& k) const {
    return size_t(uint64_t(k.x) * 73856093ull ^ uint64_t(k.y) * 19349663ull ^
                  uint64_t(k.z) * 83492791ull);
  }
};

// Merges vertices closer than `eps` (exactly equal ones when eps is 0); returns the new index
// of every vertex and the merged positions. `isCopy` marks vertices OpenMesh duplicated itself,
// whose merging is not counted.
std::vector<uint32_t> mergeVertices(const std::vector<glm::vec3>& points,
                                    const std::vector<uint8_t>& isCopy, float eps,
                                    std::vector<glm::vec3>& merged, size_t& mergedCount) {
  std::vector<uint32_t> remap(points.size());
  std::unordered_map<CellKey, std::vector<uint32_t>, CellHash> cells;
  const double cell = eps > 0.f ? double(eps) : 0.0;
  auto keyOf = [&](glm::vec3 p) {
    if (cell == 0.0) {
      int32_t b[3];
      std::memcpy(b, &p, sizeof b);
      return CellKey{b[0], b[1], b[2]};
    }
    return CellKey{int64_t(std::floor(double(p.x) / cell)), int64_t(std::floor(double(p.y) / cell)),
                   int64_t(std::floor(double(p.z) / cell))};
  };
  const int reach = cell == 0.0 ? 0 : 1;
  for (size_t v = 0; v < points.size(); ++v) {
    const glm::vec3 p = points[v] + glm::vec3(0.f);  // -0 == +0
    const CellKey key = keyOf(p);
    int64_t found = -1;
    for (int dz = -reach; dz <= reach && found < 0; ++dz)
      for (int dy = -reach; dy <= reach && found < 0; ++dy)
        for (int dx = -reach; dx <= reach && found < 0; ++dx) {
          auto it = cells.find({key.x + dx, key.y + dy, key.z + dz});
          if (it == cells.end()) continue;
          for (uint32_t r : it->second)
            if (glm::length(merged[r] - p) <= eps) {
              found = r;
              break;
            }
        }
    if (found >= 0) {
      remap[v] = uint32_t(found);
      if (!isCopy[v]) ++mergedCount;
    } else {
      remap[v] = uint32_t(merged.size());
      cells[key].push_back(remap[v]);
      merged.push_back(p);
    }
  }
  return remap;
}

TriangleMesh repairAndCheck(const std::string& path, const std::vector<glm::vec3>& points,
                            const std::vector<glm::uvec3>& triangles,
                            const std::vector<uint8_t>& isCopy, MeshReport& report,
                            const ProgressCallback& progress, float progressEnd) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::uvec3& t : triangles)
    for (int c = 0; c < 3; ++c) {
      lo = glm::min(lo, points[t[c]]);
      hi = glm::max(hi, points[t[c]]);
    }
  const float eps = 1e-7f * glm::length(hi - lo);

  std::vector<glm::vec3> merged;
  const std::vector<uint32_t> remap =
      mergeVertices(points, isCopy, eps, merged, report.duplicateVerticesMerged);

  std::vector<glm::uvec3> kept;
  kept.reserve(triangles.size());
  for (const glm::uvec3& t0 : triangles) {
    const glm::uvec3 t(remap[t0.x], remap[t0.y], remap[t0.z]);
    bool degenerate = t.x == t.y || t.y == t.z || t.x == t.z;
    if (!degenerate) {
      const glm::vec3 a = merged[t.x], b = merged[t.y], c = merged[t.z];
      const float longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
      // Twice the area over the longest edge is the smallest height: below eps it is flat.
      degenerate = glm::length(glm::cross(b - a, c - a)) <= eps * longest;
    }
    if (degenerate)
      ++report.degenerateFacesRemoved;
    else
      kept.push_back(t);
  }
  if (kept.empty())
    throwBadInput(path, "all " + std::to_string(triangles.size()) + " faces are degenerate");
  reportProgress(progress, path, 0.8f * progressEnd, "check");

  // Compact to the referenced vertices.
  TriangleMesh mesh;
  std::vector<int64_t> newIndex(merged.size(), -1);
  for (glm::uvec3& t : kept)
    for (int c = 0; c < 3; ++c) {
      if (newIndex[t[c]] < 0) {
        newIndex[t[c]] = int64_t(mesh.points.size());
        mesh.points.push_back(merged[t[c]]);
      }
      t[c] = uint32_t(newIndex[t[c]]);
    }
  mesh.triangles = std::move(kept);

  // Edge use counts: 1 = boundary, 2 = manifold, more = non-manifold.
  std::vector<uint64_t> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const glm::uvec3& t : mesh.triangles)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = t[c], b = t[(c + 1) % 3];
      edges.push_back(uint64_t(std::min(a, b)) << 32 | std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) ++report.boundaryEdges;
    if (j - i > 2) ++report.nonManifoldEdges;
    i = j;
  }
  report.vertices = mesh.points.size();
  report.faces = mesh.triangles.size();
  report.closed = report.boundaryEdges == 0;
  report.manifold = report.nonManifoldEdges == 0;
  lo = glm::vec3(INFINITY);
  hi = glm::vec3(-INFINITY);
  for (const glm::vec3& p : mesh.points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  for (int c = 0; c < 3; ++c) {
    report.bboxMin[c] = lo[c];
    report.bboxMax[c] = hi[c];
  }
  return mesh;
}

}  // namespace

namespace {

// A seekable stream over a buffer the caller owns (OpenMesh's OBJ reader reads from an
// std::istream, in two passes: it seeks back to the start).
struct MemoryBuffer : std::streambuf {
  MemoryBuffer(char* data, size_t size) { setg(data, data, data + size); }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
    char* base = dir == std::ios_base::beg ? eback() : dir == std::ios_base::cur ? gptr() : egptr();
    char* target = base + off;
    if (target < eback() || target > egptr()) return pos_type(off_type(-1));
    setg(eback(), target, egptr());
    return pos_type(off_type(target - eback()));
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
};

// OpenMesh's OBJ reader opens whatever file an `mtllib` line names, relative to the OBJ: a FIFO
// blocks it for good, a device makes it read forever. A volume tool has no use for materials,
// so an OBJ is read from memory with those lines turned into comments (line numbers stay).
bool readObjWithoutMaterials(PolyMesh& mesh, const std::string& path, uint64_t size) {
  std::string text(size_t(size), '\0');
  {
    std::ifstream in(path, std::ios::binary);
    in.read(text.data(), std::streamsize(size));
    if (!in) throwBadInput(path, "could not read the whole file");
  }
  for (size_t line = 0; line < text.size();) {
    size_t word = line;
    while (word < text.size() && (text[word] == ' ' || text[word] == '\t')) ++word;
    if (text.compare(word, 6, "mtllib") == 0) text[word] = '#';
    const size_t end = text.find('\n', line);
    if (end == std::string::npos) break;
    line = end + 1;
  }
  MemoryBuffer buffer(text.data(), text.size());
  std::istream stream(&buffer);
  OpenMesh::IO::Options options;
  return OpenMesh::IO::read_mesh(mesh, stream, ".obj", options);
}

}  // namespace

TriangleMesh loadMesh(const std::string& path, MeshReport& report, const ProgressCallback& progress,
                      float progressEnd) {
  report = MeshReport{};
  report.path = path;
  reportProgress(progress, path, 0.f, "load");
  const uint64_t size = io::checkedFileSize(path);
  const bool off = io::endsWithNoCase(path, ".off"), stl = io::endsWithNoCase(path, ".stl"),
             ply = io::endsWithNoCase(path, ".ply"), obj = io::endsWithNoCase(path, ".obj");
  if (!off && !stl && !ply && !obj)
    throwBadInput(path, "unsupported mesh format (expected .obj, .ply, .off or .stl)");
  if (off) validateAsciiOff(path);
  if (stl) validateStl(path, size);
  if (ply) validatePlyHeader(path, size);

  PolyMesh polyMesh;
  polyMesh.request_vertex_status();
  polyMesh.request_edge_status();
  polyMesh.request_face_status();
  bool ok = false;
  std::string messages;
  {
    std::lock_guard<std::mutex> lock(openMeshStreamMutex());
    OpenMeshErrorCapture capture;
    try {
      ok = obj ? readObjWithoutMaterials(polyMesh, path, size)
               : OpenMesh::IO::read_mesh(polyMesh, path);
    } catch (const std::exception& e) {
      ok = false;
      messages = e.what();
    } catch (...) {
      ok = false;
    }
    messages += capture.text();
  }
  if (!ok) {
    const std::string detail = firstLine(messages);
    throwBadInput(path, "not a readable mesh" + (detail.empty() ? "" : " (" + detail + ")"));
  }
  if (countOccurrences(messages, "invalid vertex index") > 0)
    throwBadInput(path,
                  "a face refers to a vertex that does not exist (malformed or truncated "
                  "file, or an unreadable coordinate such as nan)");
  if (polyMesh.n_faces() == 0)
    throwBadInput(path, "the mesh has no faces (empty, truncated or not a mesh)");
  reportProgress(progress, path, 0.3f * progressEnd, "load");

  std::vector<glm::vec3> points(polyMesh.n_vertices());
  std::vector<uint8_t> isCopy(points.size(), 0);
  size_t originalVertices = 0;
  for (auto v : polyMesh.vertices()) {
    const auto& p = polyMesh.point(v);
    const glm::vec3 q(p[0], p[1], p[2]);
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z))
      throwBadInput(path,
                    "vertex " + std::to_string(v.idx()) + " has a NaN or infinite coordinate");
    points[size_t(v.idx())] = q;
    isCopy[size_t(v.idx())] = polyMesh.status(v).fixed_nonmanifold() ? 1 : 0;
    originalVertices += isCopy[size_t(v.idx())] ? 0 : 1;
  }
  std::vector<glm::uvec3> triangles;
  triangles.reserve(polyMesh.n_faces());
  for (auto f : polyMesh.faces()) {
    std::vector<uint32_t> corners;
    for (auto v : polyMesh.fv_range(f)) corners.push_back(uint32_t(v.idx()));
    for (size_t k = 2; k < corners.size(); ++k)
      triangles.emplace_back(corners[0], corners[k - 1], corners[k]);
  }
  // OpenMesh drops faces with a repeated vertex before they reach the mesh: degenerate too.
  const size_t droppedFaces = countOccurrences(messages, "Face has equal vertices");
  if (ply) {
    long long declaredVertices = -1, declaredFaces = -1;
    plyCounts(path, declaredVertices, declaredFaces);
    if ((declaredVertices >= 0 && (long long)originalVertices < declaredVertices) ||
        (declaredFaces >= 0 && (long long)(polyMesh.n_faces() + droppedFaces) < declaredFaces))
      throwBadInput(path, "truncated: the header declares " + std::to_string(declaredVertices) +
                              " vertices and " + std::to_string(declaredFaces) + " faces");
  }
  reportProgress(progress, path, 0.5f * progressEnd, "repair");
  TriangleMesh mesh =
      repairAndCheck(path, points, triangles, isCopy, report, progress, progressEnd);
  report.degenerateFacesRemoved += droppedFaces;
  return mesh;
}

}  // namespace visopt::sdf
