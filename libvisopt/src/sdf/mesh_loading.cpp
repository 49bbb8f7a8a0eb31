// Mesh loading and repair. OFF and OBJ are parsed here; PLY and STL go through OpenMesh after
// their structure is checked. OpenMesh's readers are forgiving where a volume tool must not be
// (an ASCII OFF that ends early loaded as a partial mesh) and unsafe on hostile input (issue 13's
// fuzz targets: an OFF keyword's counts trusted, an OBJ face without vertices asserted, a short
// ASCII PLY grew a face without end); a face with a repeated vertex is dropped with a message on
// OpenMesh's error stream, and a face that would make an edge non-manifold is added on copies of
// its vertices. So this file validates what OpenMesh reads (binary STL size and values, the PLY
// header and body), captures OpenMesh's error stream, and then repairs and checks the triangle
// list itself.
#include "sdf/mesh_loading.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <mutex>
#include <regex>
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

// Routes OpenMesh's error stream into a string (and silences its log) for one load. OpenMesh's
// stream multiplexer allocates a wrapper at every connect that its disconnect never frees (16
// bytes per load, found by LeakSanitizer in the mesh fuzz targets), so nothing is disconnected:
// the capture is connected once per process and emptied per load, and std::cerr, which omerr()
// also writes to, is pointed at a sink while the load runs. Callers hold openMeshStreamMutex().
class OpenMeshErrorCapture {
 public:
  OpenMeshErrorCapture() : cerr_(std::cerr.rdbuf(sink_.rdbuf())) {
    stream().str({});
    stream().clear();
  }
  ~OpenMeshErrorCapture() {
    omerr() << std::flush;
    std::cerr.rdbuf(cerr_);
  }
  OpenMeshErrorCapture(const OpenMeshErrorCapture&) = delete;
  OpenMeshErrorCapture& operator=(const OpenMeshErrorCapture&) = delete;

  std::string text() {
    omerr() << std::flush;
    return stream().str();
  }

 private:
  static std::ostringstream& stream() {
    static std::ostringstream* const text = [] {
      auto* t = new std::ostringstream;  // as long-lived as OpenMesh's own streams
      omerr().connect(*t);
      omlog().disable();
      return t;
    }();
    return *text;
  }

  std::ostringstream sink_;
  std::streambuf* cerr_;
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

// Vertices and polygons as a file lists them, before triangulation and repair. `isCopy` marks
// vertices OpenMesh duplicated itself (to keep a non-manifold vertex manifold).
struct PolygonSoup {
  std::vector<glm::vec3> points;
  std::vector<uint8_t> isCopy;
  std::vector<std::vector<uint32_t>> faces;
  size_t droppedFaces = 0;  // faces OpenMesh refused for a repeated vertex
};

// ASCII OFF, read here rather than by OpenMesh (whose reader trusted a mangled keyword's counts
// and reserved 17 GB, issue 13's mesh fuzz targets): counts, vertex lines whose first three
// numbers are finite (texture coordinates, colours or normals may follow), faces whose indices
// exist. Binary, 4D and n-dimensional variants are refused.
PolygonSoup parseAsciiOff(const std::string& path) {
  PolygonSoup soup;
  std::istringstream in(readWholeFile(path));
  std::string line;
  size_t lineNumber = 0;
  if (!nextContentLine(in, line, lineNumber)) throwBadInput(path, "no OFF header");
  std::istringstream header(line);
  std::string magic;
  header >> magic;
  // OpenMesh reads "[ST][C][N][4][n]OFF [BINARY]" and trusted whatever it found after a
  // mangled keyword ("OFFN10..." made it reserve 17 GB). Accepted: ASCII OFF with texture
  // coordinates, colours or normals after each vertex's x y z.
  static const std::regex kAsciiVariants("(ST)?C?N?OFF");
  if (!std::regex_match(magic, kAsciiVariants))
    throwBadInput(path, std::regex_search(magic, std::regex("^(ST)?C?N?4?n?OFF$"))
                            ? "4D and n-dimensional OFF files are not supported"
                            : "not an OFF file (the first line is not an OFF keyword)");
  if (line.find("BINARY") != std::string::npos)
    throwBadInput(path, "binary OFF is not supported (save it as ASCII OFF, PLY or STL)");
  // Counts are whole numbers ("70 6.091" read as 70 vertices and 6 faces).
  auto count = [](std::istream& words, long long& out) {
    std::string token;
    if (!(words >> token) || token.size() > 18 ||
        token.find_first_not_of("0123456789") != std::string::npos)
      return false;
    out = std::stoll(token);
    return true;
  };
  long long counts[2] = {-1, -1};
  std::string rest;
  const std::streampos afterMagic = header.tellg();
  if (!(header >> rest)) {
    if (!nextContentLine(in, line, lineNumber))
      throwBadInput(path, "truncated: the OFF header has no vertex and face counts");
    std::istringstream countLine(line);
    if (!count(countLine, counts[0]) || !count(countLine, counts[1]))
      throwBadInput(path,
                    "line " + std::to_string(lineNumber) + ": expected the vertex and face counts");
  } else {
    header.clear();
    header.seekg(afterMagic);
    if (!count(header, counts[0]) || !count(header, counts[1]))
      throwBadInput(path,
                    "line " + std::to_string(lineNumber) + ": expected the vertex and face counts");
  }
  const long long nv = counts[0], nf = counts[1];
  if (nv <= 0 || nf <= 0)
    throwBadInput(path, "the OFF header declares " + std::to_string(nv) + " vertices and " +
                            std::to_string(nf) + " faces");
  // Each vertex and face takes at least two bytes ("0\n"): counts the file cannot hold are
  // refused before anything is reserved for them.
  const size_t bytes = in.str().size();
  if (uint64_t(nv) > bytes / 2 || uint64_t(nf) > bytes / 2)
    throwBadInput(path, "truncated: the OFF header declares " + std::to_string(nv) +
                            " vertices and " + std::to_string(nf) + " faces in " +
                            std::to_string(bytes) + " bytes");
  soup.points.reserve(size_t(nv));
  soup.faces.reserve(size_t(nf));
  for (long long v = 0; v < nv; ++v) {
    if (!nextContentLine(in, line, lineNumber))
      throwBadInput(path,
                    "truncated: " + std::to_string(v) + " of " + std::to_string(nv) + " vertices");
    const char* at = line.c_str();
    glm::vec3 p(0.f);
    for (int c = 0; c < 3; ++c) {
      char* end = nullptr;
      const float x = std::strtof(at, &end);
      if (end == at)
        throwBadInput(path, "line " + std::to_string(lineNumber) + ": expected a vertex (x y z)");
      if (!std::isfinite(x))
        throwBadInput(path, "vertex " + std::to_string(v) + " (line " + std::to_string(lineNumber) +
                                ") has a NaN or infinite coordinate");
      p[c] = x;
      at = end;
    }
    soup.points.push_back(p);
  }
  for (long long f = 0; f < nf; ++f) {
    if (!nextContentLine(in, line, lineNumber))
      throwBadInput(path,
                    "truncated: " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    std::istringstream face(line);
    long long n = 0;
    if (!(face >> n) || n < 3 || n > (1 << 16))
      throwBadInput(path, "line " + std::to_string(lineNumber) + ": expected a face (n i1 .. in)");
    std::vector<uint32_t>& corners = soup.faces.emplace_back();
    for (long long k = 0; k < n; ++k) {
      long long index = -1;
      if (!(face >> index))
        throwBadInput(path, "line " + std::to_string(lineNumber) + ": face with fewer than " +
                                std::to_string(n) + " vertex indices");
      if (index < 0 || index >= nv)
        throwBadInput(path, "line " + std::to_string(lineNumber) + ": face refers to vertex " +
                                std::to_string(index) + " of " + std::to_string(nv));
      corners.push_back(uint32_t(index));
    }
  }
  soup.isCopy.assign(soup.points.size(), 0);
  return soup;
}

// Wavefront OBJ, read here rather than by OpenMesh (whose reader asserted on a face without a
// usable vertex and opened whatever an mtllib line named): "v x y z ..." vertices (finite),
// "f" faces of three or more references "i", "i/t", "i//n" or "i/t/n" (1-based; negative ones
// count back from the last vertex). Everything else (normals, texture coordinates, groups,
// materials, lines, points) is skipped; material files are never opened.
PolygonSoup parseObj(const std::string& path) {
  PolygonSoup soup;
  std::istringstream in(readWholeFile(path));
  std::string line;
  size_t lineNumber = 0;
  while (nextContentLine(in, line, lineNumber)) {
    const char* at = line.c_str();
    while (*at == ' ' || *at == '\t') ++at;
    auto where = [&] { return "line " + std::to_string(lineNumber); };
    if (at[0] == 'v' && (at[1] == ' ' || at[1] == '\t')) {
      at += 1;
      glm::vec3 p(0.f);
      for (int c = 0; c < 3; ++c) {
        char* end = nullptr;
        const float x = std::strtof(at, &end);
        if (end == at) throwBadInput(path, where() + ": expected a vertex (v x y z)");
        if (!std::isfinite(x))
          throwBadInput(path, "vertex " + std::to_string(soup.points.size() + 1) + " (" + where() +
                                  ") has a NaN or infinite coordinate");
        p[c] = x;
        at = end;
      }
      soup.points.push_back(p);
    } else if (at[0] == 'f' && (at[1] == ' ' || at[1] == '\t')) {
      std::istringstream refs(at + 1);
      std::vector<uint32_t> corners;
      for (std::string ref; refs >> ref;) {
        char* end = nullptr;
        const long long i = std::strtoll(ref.c_str(), &end, 10);
        if (end == ref.c_str() || (*end != '\0' && *end != '/'))
          throwBadInput(path, where() + ": malformed face reference \"" + ref.substr(0, 20) + "\"");
        const long long n = static_cast<long long>(soup.points.size());
        const long long index = i > 0 ? i - 1 : n + i;
        if (i == 0 || index < 0 || index >= n)
          throwBadInput(path, where() + ": face refers to vertex " + std::to_string(i) + " of " +
                                  std::to_string(n) + " so far");
        corners.push_back(uint32_t(index));
        if (corners.size() > (1u << 16)) throwBadInput(path, where() + ": face too large");
      }
      if (corners.size() < 3)
        throwBadInput(path, where() + ": face with fewer than three vertices");
      soup.faces.push_back(std::move(corners));
    }
  }
  soup.isCopy.assign(soup.points.size(), 0);
  return soup;
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
// Then the body is walked element by element (validatePlyBody): OpenMesh's ASCII reader, given
// fewer values than the header declares, took a failed read for a list length and grew a face
// without end (an out-of-memory in the mesh fuzz targets).
struct PlyProperty {
  bool list = false;
  std::string countType, type, name;
};
struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

size_t plyTypeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "double" || t == "float64") return 8;
  return 4;  // int, uint, float and their sized names
}

bool plyTypeIsFloat(const std::string& t) {
  return t == "float" || t == "double" || t == "float32" || t == "float64";
}

void validatePlyBody(const std::string& path, std::ifstream& in, uint64_t size, bool ascii,
                     bool bigEndian, const std::vector<PlyElement>& elements, long long vertices);

// The element counts a PLY header declares.
struct PlyCounts {
  long long vertices = -1, faces = -1;
};

PlyCounts validatePlyHeader(const std::string& path, uint64_t size) {
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
  const bool ascii = line == "format ascii 1.0", bigEndian = line == "format binary_big_endian 1.0";
  std::vector<PlyElement> elements;
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
      elements.push_back({element, count, {}});
    } else if (word == "property") {
      if (element.empty() || !(words >> a)) bad();
      if (a == "list") {
        if (!(words >> b >> c >> rest) || !isScalar(b) || !isScalar(c) || b == "float" ||
            b == "double" || b == "float32" || b == "float64")
          bad();
        if (element == "face" && (rest == "vertex_indices" || rest == "vertex_index"))
          indices = true;
        elements.back().properties.push_back({true, b, c, rest});
      } else {
        if (!isScalar(a) || !(words >> b) || (words >> rest)) bad();
        elements.back().properties.push_back({false, {}, a, b});
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
  validatePlyBody(path, in, size, ascii, bigEndian, elements, vertices);
  return {vertices, faces};
}

void validatePlyBody(const std::string& path, std::ifstream& in, uint64_t size, bool ascii,
                     bool bigEndian, const std::vector<PlyElement>& elements, long long vertices) {
  constexpr long long kMaxListLength = 1 << 16;
  std::string line;
  for (const PlyElement& e : elements) {
    const bool face = e.name == "face";
    for (long long n = 0; n < e.count; ++n) {
      auto where = [&] { return e.name + " " + std::to_string(n); };
      if (ascii) {
        do {
          if (!std::getline(in, line))
            throwBadInput(path, "truncated: " + std::to_string(n) + " of " +
                                    std::to_string(e.count) + " " + e.name + " lines");
        } while (line.find_first_not_of(" \t\r") == std::string::npos);
        std::istringstream values(line);
        for (const PlyProperty& p : e.properties) {
          long long length = 1;
          if (p.list && (!(values >> length) || length < 0 || length > kMaxListLength))
            throwBadInput(path, where() + ": malformed list length for " + p.name);
          for (long long k = 0; k < length; ++k) {
            double v = 0;
            if (!(values >> v))
              throwBadInput(path, where() + ": fewer values than its properties declare");
            if (face && p.list && (v < 0 || v >= double(vertices) || v != std::floor(v)))
              throwBadInput(path, where() + " refers to vertex " + std::to_string(v) + " of " +
                                      std::to_string(vertices));
          }
        }
        std::string extra;
        if (values >> extra)
          throwBadInput(path, where() + ": more values than its properties declare");
      } else {
        for (const PlyProperty& p : e.properties) {
          uint64_t length = 1;
          if (p.list) {
            unsigned char b[8] = {};
            const size_t bytes = plyTypeSize(p.countType);
            if (!in.read(reinterpret_cast<char*>(b), std::streamsize(bytes)))
              throwBadInput(path, "truncated at " + where());
            length = 0;
            for (size_t i = 0; i < bytes; ++i)
              length = (length << 8) | b[bigEndian ? i : bytes - 1 - i];
            if (length > uint64_t(kMaxListLength))
              throwBadInput(
                  path, where() + ": list " + p.name + " of " + std::to_string(length) + " values");
          }
          const size_t item = plyTypeSize(p.type);
          if (face && p.list && !plyTypeIsFloat(p.type)) {
            for (uint64_t k = 0; k < length; ++k) {
              unsigned char b[8] = {};
              if (!in.read(reinterpret_cast<char*>(b), std::streamsize(item)))
                throwBadInput(path, "truncated at " + where());
              uint64_t v = 0;
              for (size_t i = 0; i < item; ++i) v = (v << 8) | b[bigEndian ? i : item - 1 - i];
              if (v >= uint64_t(vertices))  // negative signed values wrap to huge ones too
                throwBadInput(path, where() + " refers to a vertex beyond the " +
                                        std::to_string(vertices) + " declared");
            }
          } else {
            in.seekg(std::streamoff(length * item), std::ios::cur);
            if (!in || uint64_t(in.tellg()) > size) throwBadInput(path, "truncated at " + where());
          }
        }
      }
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
    // Clamped: a vertex ~1e38 away in a mesh of tiny extent gives a cell index beyond int64
    // (undefined to convert); far cells sharing a key only cost a distance test.
    auto index = [&](float x) {
      return int64_t(std::clamp(std::floor(double(x) / cell), -4.6e18, 4.6e18));
    };
    return CellKey{index(p.x), index(p.y), index(p.z)};
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

// PLY and STL through OpenMesh, after their structure was checked (validatePlyHeader walks a
// PLY's body, validateStl a binary STL's size and values).
PolygonSoup readWithOpenMesh(const std::string& path, uint64_t size, bool ply) {
  PlyCounts declared;
  if (ply)
    declared = validatePlyHeader(path, size);
  else
    validateStl(path, size);
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
      ok = OpenMesh::IO::read_mesh(polyMesh, path);
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
  PolygonSoup soup;
  soup.points.resize(polyMesh.n_vertices());
  soup.isCopy.assign(soup.points.size(), 0);
  size_t originalVertices = 0;
  for (auto v : polyMesh.vertices()) {
    const auto& p = polyMesh.point(v);
    const glm::vec3 q(p[0], p[1], p[2]);
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z))
      throwBadInput(path,
                    "vertex " + std::to_string(v.idx()) + " has a NaN or infinite coordinate");
    soup.points[size_t(v.idx())] = q;
    soup.isCopy[size_t(v.idx())] = polyMesh.status(v).fixed_nonmanifold() ? 1 : 0;
    originalVertices += soup.isCopy[size_t(v.idx())] ? 0 : 1;
  }
  soup.faces.reserve(polyMesh.n_faces());
  for (auto f : polyMesh.faces()) {
    std::vector<uint32_t>& corners = soup.faces.emplace_back();
    for (auto v : polyMesh.fv_range(f)) corners.push_back(uint32_t(v.idx()));
  }
  // OpenMesh drops faces with a repeated vertex before they reach the mesh: degenerate too.
  soup.droppedFaces = countOccurrences(messages, "Face has equal vertices");
  if (ply && ((long long)originalVertices < declared.vertices ||
              (long long)(polyMesh.n_faces() + soup.droppedFaces) < declared.faces))
    throwBadInput(path, "truncated: the header declares " + std::to_string(declared.vertices) +
                            " vertices and " + std::to_string(declared.faces) + " faces");
  return soup;
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
  PolygonSoup soup = off   ? parseAsciiOff(path)
                     : obj ? parseObj(path)
                           : readWithOpenMesh(path, size, ply);
  if (soup.faces.empty())
    throwBadInput(path, "the mesh has no faces (empty, truncated or not a mesh)");
  reportProgress(progress, path, 0.3f * progressEnd, "load");

  std::vector<glm::uvec3> triangles;
  triangles.reserve(soup.faces.size());
  for (const std::vector<uint32_t>& corners : soup.faces)
    for (size_t k = 2; k < corners.size(); ++k)
      triangles.emplace_back(corners[0], corners[k - 1], corners[k]);
  const std::vector<glm::vec3>& points = soup.points;
  const std::vector<uint8_t>& isCopy = soup.isCopy;
  const size_t droppedFaces = soup.droppedFaces;
  reportProgress(progress, path, 0.5f * progressEnd, "repair");
  TriangleMesh mesh =
      repairAndCheck(path, points, triangles, isCopy, report, progress, progressEnd);
  report.degenerateFacesRemoved += droppedFaces;
  return mesh;
}

}  // namespace visopt::sdf
