// Context surfaces from triangle meshes (Himmler & Günther 2026, §III-B, §IV-E): a closed mesh
// gives a filled SDF whose zero set lies within a voxel of the mesh, an open one only a thin shell;
// broken files are refused with one line naming the file; .vdb files round-trip; the CLI maps
// errors to exit codes.
#include <sys/stat.h>
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "core/field_view.h"
#include "visopt/error.h"
#include "visopt/sdf.h"

namespace fs = std::filesystem;
using namespace visopt;

namespace {

struct Mesh {
  std::vector<glm::vec3> v;
  std::vector<glm::uvec3> f;
};

// Icosahedron subdivided `levels` times, projected onto the sphere (centre c, radius r).
Mesh icosphere(int levels, glm::vec3 c, float r) {
  const float t = (1.f + std::sqrt(5.f)) / 2.f;
  Mesh m;
  m.v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  m.f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : m.v) p = glm::normalize(p);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<unsigned, unsigned>, unsigned> mid;
    auto midpoint = [&](unsigned a, unsigned b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.v.push_back(glm::normalize(m.v[a] + m.v[b]));
      return mid[key] = unsigned(m.v.size() - 1);
    };
    std::vector<glm::uvec3> next;
    for (auto t3 : m.f) {
      unsigned a = midpoint(t3.x, t3.y), b = midpoint(t3.y, t3.z), cc = midpoint(t3.z, t3.x);
      next.insert(next.end(), {{t3.x, a, cc}, {t3.y, b, a}, {t3.z, cc, b}, {a, b, cc}});
    }
    m.f = next;
  }
  for (auto& p : m.v) p = c + r * p;
  return m;
}

std::string tmp(const std::string& name) {
  const fs::path dir = fs::path(VISOPT_TEST_TMP) / "mesh_sdf";
  fs::create_directories(dir);
  return (dir / name).string();
}

void writeOff(const Mesh& m, const std::string& path) {
  std::ofstream o(path);
  o << "OFF\n" << m.v.size() << " " << m.f.size() << " 0\n";
  o.precision(12);
  for (auto p : m.v) o << p.x << " " << p.y << " " << p.z << "\n";
  for (auto t : m.f) o << "3 " << t.x << " " << t.y << " " << t.z << "\n";
}
void writeObj(const Mesh& m, const std::string& path) {
  std::ofstream o(path);
  o.precision(12);
  for (auto p : m.v) o << "v " << p.x << " " << p.y << " " << p.z << "\n";
  for (auto t : m.f) o << "f " << t.x + 1 << " " << t.y + 1 << " " << t.z + 1 << "\n";
}
void writePly(const Mesh& m, const std::string& path) {
  std::ofstream o(path);
  o.precision(12);
  o << "ply\nformat ascii 1.0\nelement vertex " << m.v.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.f.size()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (auto p : m.v) o << p.x << " " << p.y << " " << p.z << "\n";
  for (auto t : m.f) o << "3 " << t.x << " " << t.y << " " << t.z << "\n";
}
void writeStl(const Mesh& m, const std::string& path) {  // binary: one vertex copy per corner
  std::ofstream o(path, std::ios::binary);
  char header[80] = "visopt test";
  o.write(header, 80);
  const uint32_t n = uint32_t(m.f.size());
  o.write(reinterpret_cast<const char*>(&n), 4);
  for (auto t : m.f) {
    float data[12] = {0, 0, 0};
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) data[3 + 3 * c + a] = m.v[t[c]][a];
    o.write(reinterpret_cast<const char*>(data), sizeof data);
    const uint16_t attr = 0;
    o.write(reinterpret_cast<const char*>(&attr), 2);
  }
}
void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

float sampleAt(const Field3D& f, glm::vec3 world) {
  return FieldView(f).sample(f.grid().worldToIndex(world));
}

glm::vec3 worldOf(const GridSpec& g, int i, int j, int k) {
  return g.indexToWorld(glm::vec3(float(i), float(j), float(k)));
}

// |grad phi| by central differences in world units (axes may be rotated, spacing anisotropic).
float gradientNorm(const Field3D& f, int i, int j, int k) {
  const GridSpec& g = f.grid();
  FieldView v(f);
  glm::vec3 d;
  d.x = (v.at(i + 1, j, k) - v.at(i - 1, j, k)) / (2.f * g.spacing.x);
  d.y = (v.at(i, j + 1, k) - v.at(i, j - 1, k)) / (2.f * g.spacing.y);
  d.z = (v.at(i, j, k + 1) - v.at(i, j, k - 1)) / (2.f * g.spacing.z);
  return glm::length(d);
}

// Fraction of voxels with |phi| < band (away from the border) whose |grad| is in [0.9, 1.1].
float unitGradientFraction(const Field3D& f, float band, int* count = nullptr) {
  const GridSpec& g = f.grid();
  int total = 0, good = 0;
  for (int k = 1; k < g.dims.z - 1; ++k)
    for (int j = 1; j < g.dims.y - 1; ++j)
      for (int i = 1; i < g.dims.x - 1; ++i) {
        if (std::fabs(f.get(g.linearIndex(i, j, k))) >= band) continue;
        ++total;
        const float n = gradientNorm(f, i, j, k);
        if (n >= 0.9f && n <= 1.1f) ++good;
      }
  if (count) *count = total;
  return total ? float(good) / float(total) : 0.f;
}

template <class F>
ErrorKind errorKindOf(F&& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const Error& e) {
    if (message) *message = e.what();
    return e.kind();
  }
  ADD_FAILURE() << "no visopt::Error was thrown";
  return ErrorKind::Failure;
}

MeshSdfOptions filledOptions(float voxel) {
  MeshSdfOptions o;
  o.filled = true;
  o.voxelSize = voxel;
  o.paddingVoxels = 3;
  return o;
}

const glm::vec3 kCentre(0.3f, -0.2f, 0.5f);
constexpr float kRadius = 1.f;

// Largest gap between the icosphere's faces and the true sphere (face centroid depth).
float sagitta(const Mesh& m) {
  float s = 0.f;
  for (auto t : m.f)
    s = std::max(s, kRadius - glm::length((m.v[t.x] + m.v[t.y] + m.v[t.z]) / 3.f - kCentre));
  return s;
}

// Checks a filled SDF of the icosphere: zero set on the mesh, inside negative, world units.
void expectSphereSdf(const Field3D& sdf, const Mesh& m, float tolerance) {
  const GridSpec& g = sdf.grid();
  const float voxel = glm::max(g.spacing.x, glm::max(g.spacing.y, g.spacing.z));
  for (auto p : m.v) ASSERT_LT(std::fabs(sampleAt(sdf, p)), voxel) << "vertex " << p.x;
  for (auto t : m.f) {
    const glm::vec3 c = (m.v[t.x] + m.v[t.y] + m.v[t.z]) / 3.f;
    ASSERT_LT(std::fabs(sampleAt(sdf, c)), voxel);
  }
  EXPECT_NEAR(sampleAt(sdf, kCentre), -kRadius, voxel);
  // Everywhere on the grid: the analytic distance to the sphere, within the mesh's deviation
  // from the sphere plus the tolerance; signs exactly right away from the surface.
  const float s = sagitta(m);
  size_t bad = 0;
  float worst = 0.f;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const float exact = glm::length(worldOf(g, i, j, k) - kCentre) - kRadius;
        const float phi = sdf.get(g.linearIndex(i, j, k));
        worst = std::max(worst, std::fabs(phi - exact) - s);
        // OpenVDB's exact narrow band near the surface; closest-triangle propagation beyond.
        const float allowed = std::fabs(exact) < 2.f * voxel ? tolerance : tolerance + 0.5f * voxel;
        if (std::fabs(phi - exact) > s + allowed) ++bad;
        if (exact < -s - 1e-4f && phi >= 0.f) ++bad;
        if (exact > 1e-4f && phi <= 0.f) ++bad;
      }
  EXPECT_EQ(bad, 0u) << "worst " << worst << " (" << worst / voxel << " voxels)";
  int count = 0;
  EXPECT_GE(unitGradientFraction(sdf, 3.f * voxel, &count), 0.99f);
  EXPECT_GT(count, 100);
}

}  // namespace

TEST(MeshSdf, ClosedSphereGivesFilledSdfWithZeroSetOnTheMesh) {
  const Mesh m = icosphere(3, kCentre, kRadius);
  const std::string path = tmp("sphere.off");
  writeOff(m, path);
  MeshReport report;
  const float voxel = 0.05f;
  Field3D sdf = sdfFromMesh(path, filledOptions(voxel), Precision::FP32, nullptr, &report);
  EXPECT_EQ(sdf.name(), "sdf");
  EXPECT_EQ(report.path, path);
  EXPECT_EQ(report.vertices, m.v.size());
  EXPECT_EQ(report.faces, m.f.size());
  EXPECT_TRUE(report.closed);
  EXPECT_TRUE(report.manifold);
  EXPECT_EQ(report.boundaryEdges, 0u);
  EXPECT_EQ(report.duplicateVerticesMerged, 0u);
  EXPECT_NEAR(report.bboxMin[0], kCentre.x - kRadius, 1e-5f);
  EXPECT_NEAR(report.bboxMax[2], kCentre.z + kRadius, 1e-5f);
  // The grid: cubic voxels around the bounding box with 3 voxels of padding.
  const GridSpec& g = sdf.grid();
  EXPECT_EQ(g.spacing, glm::vec3(voxel));
  EXPECT_GE(g.dims.x, int(2.f * kRadius / voxel) + 7);
  EXPECT_LE(g.dims.x, int(2.f * kRadius / voxel) + 9);
  expectSphereSdf(sdf, m, 0.1f * voxel);
  // Far outside (the grid's corner) is positive.
  EXPECT_GT(sdf.get(0), 0.f);
}

TEST(MeshSdf, EveryFormatLoads) {
  const Mesh m = icosphere(2, kCentre, kRadius);
  const std::map<std::string, void (*)(const Mesh&, const std::string&)> writers = {
      {"obj", writeObj}, {"ply", writePly}, {"stl", writeStl}, {"off", writeOff}};
  for (const auto& [ext, write] : writers) {
    SCOPED_TRACE(ext);
    const std::string path = tmp("formats." + ext);
    write(m, path);
    MeshReport report;
    Field3D sdf = sdfFromMesh(path, filledOptions(0.08f), Precision::FP32, nullptr, &report);
    EXPECT_EQ(report.vertices, m.v.size());
    EXPECT_EQ(report.faces, m.f.size());
    EXPECT_TRUE(report.closed && report.manifold);
    EXPECT_NEAR(sampleAt(sdf, kCentre), -kRadius, 0.08f);
  }
}

// An OBJ whose `mtllib` names a FIFO (no writer: opening it blocks for good) or a device loads
// without reading it: materials are never opened (issue 13). Without the guard this test hangs
// until ctest's timeout.
TEST(MeshSdf, ObjMaterialReferencesAreNeverOpened) {
  const Mesh m = icosphere(2, kCentre, kRadius);
  const std::string fifo = tmp("materials_fifo.mtl");
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& library : {std::string("materials_fifo.mtl"), std::string("/dev/zero")}) {
    SCOPED_TRACE(library);
    const std::string path = tmp("with_materials.obj");
    writeObj(m, path);
    {
      std::ifstream in(path);
      std::stringstream body;
      body << in.rdbuf();
      writeText(path,
                "# exported with materials\n  mtllib " + library + "\nusemtl skin\n" + body.str());
    }
    MeshReport report;
    const Field3D sdf = sdfFromMesh(path, filledOptions(0.08f), Precision::FP32, nullptr, &report);
    EXPECT_EQ(report.faces, m.f.size());
    EXPECT_NEAR(sampleAt(sdf, kCentre), -kRadius, 0.08f);
  }
  std::remove(fifo.c_str());
}

TEST(MeshSdf, Fp16StorageKeepsTheSurface) {
  const Mesh m = icosphere(2, kCentre, kRadius);
  const std::string path = tmp("sphere16.off");
  writeOff(m, path);
  Field3D sdf = sdfFromMesh(path, filledOptions(0.08f), Precision::FP16, nullptr);
  EXPECT_EQ(sdf.precision(), Precision::FP16);
  for (auto p : m.v) ASSERT_LT(std::fabs(sampleAt(sdf, p)), 0.08f);
}

TEST(MeshSdf, OpenMeshIsRefusedAsFilledAndAcceptedAsShell) {
  Mesh m = icosphere(3, kCentre, kRadius);
  std::vector<glm::uvec3> kept;
  for (auto t : m.f)
    if (((m.v[t.x] + m.v[t.y] + m.v[t.z]) / 3.f - kCentre).z < 0.8f * kRadius) kept.push_back(t);
  ASSERT_LT(kept.size(), m.f.size());
  m.f = kept;
  const std::string path = tmp("open_sphere.obj");
  writeObj(m, path);

  std::string message;
  EXPECT_EQ(errorKindOf([&] { sdfFromMesh(path, filledOptions(0.05f), Precision::FP32, nullptr); },
                        &message),
            ErrorKind::BadInput);
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("open"), std::string::npos) << message;
  EXPECT_NE(message.find("boundary edges"), std::string::npos) << message;
  EXPECT_NE(message.find("--shell"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);

  MeshSdfOptions o = filledOptions(0.05f);
  o.filled = false;
  o.shellThickness = 0.1f;
  MeshReport report;
  Field3D shell = sdfFromMesh(path, o, Precision::FP32, nullptr, &report);
  EXPECT_FALSE(report.closed);
  EXPECT_TRUE(report.manifold);
  EXPECT_GT(report.boundaryEdges, 0u);
  // phi = |dist| - d: -d on the mesh, R - d at the centre, and positive far away.
  for (auto t : m.f)
    for (int c = 0; c < 3; ++c)  // trilinear across the kink of |u| rounds it up (< 1 voxel)
      ASSERT_NEAR(sampleAt(shell, m.v[t[c]]), -0.1f, 0.05f);
  EXPECT_NEAR(sampleAt(shell, kCentre), kRadius - 0.1f, 0.05f);
  EXPECT_GT(shell.get(0), 0.f);
  // Inside the removed cap, outside the remaining sphere: positive (not inside anything).
  EXPECT_GT(sampleAt(shell, kCentre + glm::vec3(0, 0, 0.95f * kRadius)), 0.f);
  // Near the shell's zero level set (away from the kink of |u| on the mesh itself).
  EXPECT_GE(unitGradientFraction(shell, 0.04f), 0.95f);
}

TEST(MeshSdf, BrokenFilesAreRefusedNamingTheFile) {
  const Mesh m = icosphere(1, kCentre, kRadius);
  std::ostringstream good;
  {
    const std::string p = tmp("good.off");
    writeOff(m, p);
    std::ifstream in(p);
    good << in.rdbuf();
  }
  const std::string text = good.str();
  std::string nanText = text;
  nanText.replace(nanText.find('\n', 4) + 1, 0, "nan 0 0\n");  // becomes vertex 0
  nanText.erase(nanText.find('\n', nanText.find("nan")) + 1,
                nanText.find('\n', nanText.find('\n', nanText.find("nan")) + 1) -
                    nanText.find('\n', nanText.find("nan")));  // drop the old vertex 0

  std::map<std::string, std::string> cases = {
      {"empty.off", ""},
      {"truncated.off", text.substr(0, text.size() / 2)},
      {"truncated_header.off", "OFF\n12"},
      {"nan.off", nanText},
      {"garbage.off", "this is not a mesh\n\x01\x02\x03"},
      {"garbage.ply", "ply\nformat nonsense\n\xff\xfe"},
      {"garbage.obj", "hello world\nnot an obj\n"},
      {"garbage.stl", std::string(300, '\x07')},
      {"bad_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"},
      {"unknown.xyz", "1 2 3\n"}};
  // Binary STL with a NaN vertex, and one cut short.
  {
    writeStl(m, tmp("nan.stl"));
    std::fstream s(tmp("nan.stl"), std::ios::in | std::ios::out | std::ios::binary);
    s.seekp(84 + 12);
    const float nan = std::nanf("");
    s.write(reinterpret_cast<const char*>(&nan), 4);
  }
  {
    writeStl(m, tmp("truncated.stl"));
    fs::resize_file(tmp("truncated.stl"), 84 + 50 * 10 + 20);
  }
  {
    writePly(m, tmp("truncated.ply"));
    fs::resize_file(tmp("truncated.ply"), fs::file_size(tmp("truncated.ply")) / 2);
  }
  std::vector<std::string> paths = {tmp("nan.stl"), tmp("truncated.stl"), tmp("truncated.ply"),
                                    tmp("missing.off")};
  for (const auto& [name, content] : cases) {
    writeText(tmp(name), content);
    paths.push_back(tmp(name));
  }
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    std::string message;
    EXPECT_EQ(errorKindOf(
                  [&] {
                    MeshSdfOptions o = filledOptions(0.1f);
                    o.filled = false;  // even a thin shell needs a readable mesh
                    o.shellThickness = 0.1f;
                    sdfFromMesh(path, o, Precision::FP32, nullptr);
                  },
                  &message),
              ErrorKind::BadInput);
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // The NaN is named as such where the reader gets that far.
  std::string message;
  errorKindOf([&] { sdfFromMesh(tmp("nan.stl"), filledOptions(0.1f), Precision::FP32, nullptr); },
              &message);
  EXPECT_NE(message.find("NaN"), std::string::npos) << message;
  errorKindOf([&] { sdfFromMesh(tmp("nan.off"), filledOptions(0.1f), Precision::FP32, nullptr); },
              &message);
  EXPECT_NE(message.find("NaN"), std::string::npos) << message;
}

TEST(MeshSdf, DuplicateVerticesAndDegenerateFacesAreRepairedAndReported) {
  // A cube of half-side 1 whose faces each own their 4 vertices (24 vertices for 8 corners),
  // one corner copy nudged by far less than 1e-7 of the diagonal, plus a face with a repeated
  // vertex and a zero-area face along an existing edge.
  Mesh m;
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  auto corner = [](int c) {
    return glm::vec3(c & 1 ? 1.f : -1.f, c & 2 ? 1.f : -1.f, c & 4 ? 1.f : -1.f);
  };
  for (const auto& q : quads) {
    const unsigned base = unsigned(m.v.size());
    for (int c = 0; c < 4; ++c) m.v.push_back(corner(q[c]));
    m.f.push_back({base, base + 1, base + 2});
    m.f.push_back({base, base + 2, base + 3});
  }
  m.v[5].x += 1e-9f * 4.f;  // within 1e-7 of the diagonal (~3.46)
  m.f.push_back({0, 0, 1});
  m.v.push_back(0.5f * (m.v[0] + m.v[1]));  // midpoint of the edge 0-1
  m.f.push_back({0, unsigned(m.v.size() - 1), 1});
  const std::string path = tmp("dirty_cube.off");
  writeOff(m, path);

  MeshReport report;
  const float voxel = 0.1f;
  Field3D sdf = sdfFromMesh(path, filledOptions(voxel), Precision::FP32, nullptr, &report);
  EXPECT_EQ(report.vertices, 8u);
  EXPECT_EQ(report.faces, 12u);
  EXPECT_EQ(report.duplicateVerticesMerged, 16u);
  EXPECT_EQ(report.degenerateFacesRemoved, 2u);
  EXPECT_TRUE(report.closed);
  EXPECT_TRUE(report.manifold);
  // The box SDF everywhere on the grid.
  const GridSpec& g = sdf.grid();
  float worst = 0.f;
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::vec3 q = glm::abs(worldOf(g, i, j, k)) - glm::vec3(1.f);
        const float exact = glm::length(glm::max(q, glm::vec3(0.f))) +
                            std::min(std::max(q.x, std::max(q.y, q.z)), 0.f);
        worst = std::max(worst, std::fabs(sdf.get(g.linearIndex(i, j, k)) - exact));
      }
  EXPECT_LT(worst, 0.1f * voxel);
}

TEST(MeshSdf, NonManifoldMeshIsRefusedAsFilled) {
  // Two tetrahedra sharing one edge: that edge has four faces.
  Mesh m;
  m.v = {{0, 0, 0},       {1, 0, 0},        {0.5f, 1, 0.3f},
         {0.5f, 0.2f, 1}, {0.5f, -1, 0.3f}, {0.5f, -0.2f, -1}};
  m.f = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 4, 1}, {0, 1, 5}, {0, 5, 4}, {1, 4, 5}};
  const std::string path = tmp("bowtie.off");
  writeOff(m, path);
  std::string message;
  EXPECT_EQ(errorKindOf([&] { sdfFromMesh(path, filledOptions(0.1f), Precision::FP32, nullptr); },
                        &message),
            ErrorKind::BadInput);
  EXPECT_NE(message.find("non-manifold"), std::string::npos) << message;
  EXPECT_NE(message.find("--shell"), std::string::npos) << message;
  MeshSdfOptions o = filledOptions(0.1f);
  o.filled = false;
  o.shellThickness = 0.05f;
  MeshReport report;
  sdfFromMesh(path, o, Precision::FP32, nullptr, &report);
  EXPECT_FALSE(report.manifold);
  EXPECT_GE(report.nonManifoldEdges, 1u);
  EXPECT_EQ(report.faces, 8u);
}

// A volume's grid: anisotropic spacing and a rotated frame; the SDF is still in world units.
GridSpec anisotropicGrid() {
  GridSpec g;
  g.dims = glm::ivec3(44, 34, 24);
  g.spacing = glm::vec3(0.06f, 0.08f, 0.11f);
  const float a = 0.5f;
  g.direction = glm::mat3(glm::vec3(std::cos(a), std::sin(a), 0.f),
                          glm::vec3(-std::sin(a), std::cos(a), 0.f), glm::vec3(0.f, 0.f, 1.f));
  // Centre the grid on the sphere.
  const glm::vec3 half = 0.5f * glm::vec3(g.dims - 1) * g.spacing;
  g.origin = kCentre - g.direction * half;
  return g;
}

TEST(MeshSdf, AnisotropicRotatedLikeGrid) {
  const Mesh m = icosphere(3, kCentre, kRadius);
  const std::string path = tmp("sphere_like.stl");
  writeStl(m, path);
  MeshSdfOptions o;
  o.like = anisotropicGrid();
  Field3D sdf = sdfFromMesh(path, o, Precision::FP32, nullptr);
  EXPECT_EQ(sdf.grid(), o.like);
  // Trilinear resampling from cubic voxels of the smallest spacing.
  expectSphereSdf(sdf, m, 0.5f * o.like.minSpacing());
}

TEST(MeshSdf, VdbRoundTrip) {
  const Mesh m = icosphere(3, kCentre, kRadius);
  const std::string meshPath = tmp("sphere_rt.off");
  writeOff(m, meshPath);
  for (bool anisotropic : {false, true}) {
    SCOPED_TRACE(anisotropic ? "anisotropic" : "cubic");
    MeshSdfOptions o = filledOptions(0.05f);
    if (anisotropic) o.like = anisotropicGrid();
    Field3D sdf = sdfFromMesh(meshPath, o, Precision::FP32, nullptr);
    const GridSpec& g = sdf.grid();
    const std::string vdb = tmp(anisotropic ? "rt_aniso.vdb" : "rt.vdb");
    const float band = 3.f;
    writeSdfVdb(sdf, vdb, band);
    ASSERT_TRUE(fs::exists(vdb));
    const float background = band * std::max(g.spacing.x, std::max(g.spacing.y, g.spacing.z));

    // On the original grid: equal in the band, the right sign beyond it.
    Field3D back = readSdfVdb(vdb, g, Precision::FP32, nullptr);
    EXPECT_EQ(back.name(), "sdf");
    EXPECT_EQ(back.grid(), g);
    size_t bad = 0;
    for (size_t i = 0; i < sdf.size(); ++i) {
      const float a = sdf.get(i), b = back.get(i);
      if (std::fabs(a) < background - 1e-4f ? std::fabs(a - b) > 1e-5f : (a < 0) != (b < 0)) ++bad;
    }
    EXPECT_EQ(bad, 0u);

    // On the file's own grid (the active box): same spacing and frame, aligned voxels.
    Field3D own = readSdfVdb(vdb, GridSpec{glm::ivec3(0)}, Precision::FP32, nullptr);
    const GridSpec& h = own.grid();
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(h.spacing[c], g.spacing[c], 1e-6f);
      for (int r = 0; r < 3; ++r) EXPECT_NEAR(h.direction[c][r], g.direction[c][r], 1e-5f);
    }
    const glm::vec3 offset = g.worldToIndex(h.origin);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(offset[c], std::round(offset[c]), 1e-3f);
    bad = 0;
    for (int k = 0; k < h.dims.z; ++k)
      for (int j = 0; j < h.dims.y; ++j)
        for (int i = 0; i < h.dims.x; ++i) {
          const glm::ivec3 o3 = glm::ivec3(glm::round(offset)) + glm::ivec3(i, j, k);
          if (glm::any(glm::lessThan(o3, glm::ivec3(0))) ||
              glm::any(glm::greaterThanEqual(o3, g.dims)))
            continue;
          const float a = sdf.get(g.linearIndex(o3.x, o3.y, o3.z));
          const float b = own.get(h.linearIndex(i, j, k));
          if (std::fabs(a) < background - 1e-4f ? std::fabs(a - b) > 1e-5f : (a < 0) != (b < 0))
            ++bad;
        }
    EXPECT_EQ(bad, 0u);
  }
}

TEST(MeshSdf, CorruptOrMissingVdbIsRefused) {
  const Mesh m = icosphere(2, kCentre, kRadius);
  const std::string meshPath = tmp("sphere_vdb.off");
  writeOff(m, meshPath);
  Field3D sdf = sdfFromMesh(meshPath, filledOptions(0.1f), Precision::FP32, nullptr);
  const std::string good = tmp("good.vdb");
  writeSdfVdb(sdf, good);
  writeText(tmp("garbage.vdb"), "definitely not an OpenVDB file, just some text of some length");
  writeText(tmp("empty.vdb"), "");
  fs::copy_file(good, tmp("truncated.vdb"), fs::copy_options::overwrite_existing);
  fs::resize_file(tmp("truncated.vdb"), fs::file_size(good) / 2);
  for (const std::string& path :
       {tmp("garbage.vdb"), tmp("empty.vdb"), tmp("truncated.vdb"), tmp("missing.vdb")}) {
    SCOPED_TRACE(path);
    std::string message;
    EXPECT_EQ(
        errorKindOf([&] { readSdfVdb(path, GridSpec{glm::ivec3(0)}, Precision::FP32, nullptr); },
                    &message),
        ErrorKind::BadInput);
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(MeshSdf, CancellationThrowsCancelled) {
  const Mesh m = icosphere(3, kCentre, kRadius);
  const std::string path = tmp("sphere_cancel.off");
  writeOff(m, path);
  std::vector<std::string> stages;
  Field3D sdf = sdfFromMesh(path, filledOptions(0.05f), Precision::FP32, nullptr, nullptr,
                            [&](float f, const std::string& stage) {
                              EXPECT_GE(f, 0.f);
                              EXPECT_LE(f, 1.f);
                              if (stages.empty() || stages.back() != stage) stages.push_back(stage);
                              return true;
                            });
  for (const char* s : {"load", "repair", "check", "distance", "resample"})
    EXPECT_NE(std::find(stages.begin(), stages.end(), s), stages.end()) << s;

  for (const std::string stop : {"load", "check", "distance", "resample"}) {
    SCOPED_TRACE(stop);
    int distanceCalls = 0;
    std::string message;
    EXPECT_EQ(errorKindOf(
                  [&] {
                    sdfFromMesh(path, filledOptions(0.05f), Precision::FP32, nullptr, nullptr,
                                [&](float, const std::string& stage) {
                                  // For "distance", let the first call through so the stop
                                  // comes from inside the distance computation.
                                  if (stage == "distance")
                                    return stop != stage || distanceCalls++ < 1;
                                  return stage != stop;
                                });
                  },
                  &message),
              ErrorKind::Cancelled);
    EXPECT_EQ(message, path + ": cancelled");
  }
}

TEST(MeshSdf, BadOptionsAreUsageErrors) {
  const Mesh m = icosphere(1, kCentre, kRadius);
  const std::string path = tmp("sphere_opts.off");
  writeOff(m, path);
  MeshSdfOptions noGrid;
  EXPECT_EQ(errorKindOf([&] { sdfFromMesh(path, noGrid, Precision::FP32, nullptr); }),
            ErrorKind::Usage);
  MeshSdfOptions noThickness = filledOptions(0.1f);
  noThickness.filled = false;
  EXPECT_EQ(errorKindOf([&] { sdfFromMesh(path, noThickness, Precision::FP32, nullptr); }),
            ErrorKind::Usage);
}

// ---- the CLI --------------------------------------------------------------------------------

namespace {

using Result = visopt::testing::CliResult;

Result runCli(const std::string& args) {
  return visopt::testing::runCli(args, "mesh-sdf-cli");
}

}  // namespace

TEST(MeshSdfCli, ExitCodes) {
  const Mesh m = icosphere(2, kCentre, kRadius);
  const std::string mesh = tmp("cli_sphere.ply");
  writePly(m, mesh);
  const std::string out = tmp("cli_sphere.vdb");
  fs::remove(out);

  Result ok =
      runCli("sdf --mesh " + mesh + " --filled --voxel 0.1 --padding 2 --out " + out + " --json");
  ASSERT_EQ(ok.code, 0) << ok.err;
  ASSERT_TRUE(fs::exists(out));
  const nlohmann::json j = nlohmann::json::parse(ok.out);
  EXPECT_EQ(j["mesh"]["faces"], m.f.size());
  EXPECT_EQ(j["mesh"]["closed"], true);
  EXPECT_EQ(j["out"], out);
  EXPECT_GT(j["time_ms"].get<double>(), 0.0);
  EXPECT_EQ(j["grid"]["dims"].size(), 3u);
  Field3D back = readSdfVdb(out, GridSpec{glm::ivec3(0)}, Precision::FP32, nullptr);
  EXPECT_NEAR(sampleAt(back, kCentre + glm::vec3(kRadius, 0, 0)), 0.f, 0.1f);
  EXPECT_NE(ok.err.find('%'), std::string::npos);  // progress on stderr

  writeText(tmp("cli_broken.off"), "OFF\n3 1 0\n0 0 0\n");
  Result broken = runCli("sdf --mesh " + tmp("cli_broken.off") + " --filled --voxel 0.1 --out " +
                         tmp("cli_broken.vdb"));
  EXPECT_EQ(broken.code, 2) << broken.err;
  EXPECT_NE(broken.err.find(tmp("cli_broken.off")), std::string::npos) << broken.err;
  EXPECT_FALSE(fs::exists(tmp("cli_broken.vdb")));

  Result both = runCli("sdf --mesh " + mesh + " --filled --shell 0.1 --voxel 0.1 --out " +
                       tmp("cli_both.vdb"));
  EXPECT_EQ(both.code, 1) << both.err;
  Result neither = runCli("sdf --mesh " + mesh + " --voxel 0.1 --out " + tmp("cli_n.vdb"));
  EXPECT_EQ(neither.code, 1) << neither.err;
  Result noGrid = runCli("sdf --mesh " + mesh + " --filled --out " + tmp("cli_n.vdb"));
  EXPECT_EQ(noGrid.code, 1) << noGrid.err;

  // An open mesh: --filled is bad input with the thin-shell hint, --shell works.
  Mesh open = m;
  open.f.pop_back();
  writeOff(open, tmp("cli_open.off"));
  Result filledOpen = runCli("sdf --mesh " + tmp("cli_open.off") + " --filled --voxel 0.1 --out " +
                             tmp("cli_open.vdb"));
  EXPECT_EQ(filledOpen.code, 2);
  EXPECT_NE(filledOpen.err.find("--shell"), std::string::npos) << filledOpen.err;
  Result shellOpen = runCli("sdf --mesh " + tmp("cli_open.off") +
                            " --shell 0.05 --voxel 0.1 --out " + tmp("cli_open.vdb"));
  EXPECT_EQ(shellOpen.code, 0) << shellOpen.err;
  EXPECT_TRUE(fs::exists(tmp("cli_open.vdb")));
}

// ---- real meshes ------------------------------------------------------------------------------

namespace {

std::string dataMesh(const std::string& name) {
  return (fs::path(VISOPT_DATA_DIR) / "meshes" / name).string();
}

std::vector<glm::vec3> offVertices(const std::string& path) {
  std::ifstream in(path);
  std::string magic;
  size_t nv = 0, nf = 0, ne = 0;
  in >> magic >> nv >> nf >> ne;
  std::vector<glm::vec3> v(nv);
  for (auto& p : v) in >> p.x >> p.y >> p.z;
  return v;
}

// A voxel size giving at most ~`cells` voxels along the mesh's longest side.
float voxelFor(const std::string& path, int cells) {
  MeshSdfOptions o;
  o.filled = false;
  o.shellThickness = 1.f;
  o.voxelSize = 1e30f;  // a 7^3 grid: only the report matters
  MeshReport report;
  sdfFromMesh(path, o, Precision::FP32, nullptr, &report);
  float longest = 0.f;
  for (int c = 0; c < 3; ++c) longest = std::max(longest, report.bboxMax[c] - report.bboxMin[c]);
  return longest / float(cells);
}

}  // namespace

TEST(MeshSdfData, BunnyIsClosedAndFills) {
  const std::string path = dataMesh("bunny00.off");
  if (!fs::exists(path)) GTEST_SKIP() << path << " is absent (see datasets-scripts)";
  const float voxel = voxelFor(path, 120);
  MeshReport report;
  const auto start = std::chrono::steady_clock::now();
  Field3D sdf = sdfFromMesh(path, filledOptions(voxel), Precision::FP32, nullptr, &report);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const GridSpec& g = sdf.grid();
  std::printf("bunny00.off -> %dx%dx%d filled SDF in %.0f ms\n", g.dims.x, g.dims.y, g.dims.z, ms);
  RecordProperty("bunny_ms", int(ms));
  EXPECT_TRUE(report.closed);
  EXPECT_TRUE(report.manifold);
  EXPECT_LE(g.voxelCount(), size_t(128 * 128 * 128));
  const std::vector<glm::vec3> vertices = offVertices(path);
  for (size_t i = 0; i < vertices.size(); i += 7)
    ASSERT_LT(std::fabs(sampleAt(sdf, vertices[i])), voxel) << "vertex " << i;
  size_t inside = 0;
  for (size_t i = 0; i < sdf.size(); ++i) inside += sdf.get(i) < 0.f;
  EXPECT_GT(inside, sdf.size() / 20);
  EXPECT_GT(sdf.get(0), 0.f);
  EXPECT_GT(sdf.get(sdf.size() - 1), 0.f);
  EXPECT_GE(unitGradientFraction(sdf, 2.f * voxel), 0.9f);
}

TEST(MeshSdfData, HeadIsOpenAndOnlyAShell) {
  const std::string path = dataMesh("head.off");
  if (!fs::exists(path)) GTEST_SKIP() << path << " is absent (see datasets-scripts)";
  const float voxel = voxelFor(path, 100);
  std::string message;
  EXPECT_EQ(errorKindOf([&] { sdfFromMesh(path, filledOptions(voxel), Precision::FP32, nullptr); },
                        &message),
            ErrorKind::BadInput);
  EXPECT_NE(message.find("--shell"), std::string::npos) << message;
  MeshSdfOptions o = filledOptions(voxel);
  o.filled = false;
  o.shellThickness = 2.f * voxel;
  MeshReport report;
  Field3D shell = sdfFromMesh(path, o, Precision::FP32, nullptr, &report);
  EXPECT_FALSE(report.closed);
  const std::vector<glm::vec3> vertices = offVertices(path);
  for (size_t i = 0; i < vertices.size(); i += 3)
    ASSERT_NEAR(sampleAt(shell, vertices[i]), -o.shellThickness, voxel) << "vertex " << i;
}

// PLY mutants that crashed or hung OpenMesh's reader (tests/regression/meshes, named for the
// damage and what it did): the header is checked line by line first, and each is refused as bad
// input naming the file (a hang would run into ctest's timeout). A valid PLY still loads.
TEST(MeshRegression, MalformedPlyHeadersAreRefusedBeforeOpenMeshParsesThem) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(
           std::filesystem::path(VISOPT_REGRESSION_DIR) / "meshes")) {
    const std::string path = entry.path().string();
    std::string message;
    EXPECT_EQ(errorKindOf([&] { sdfFromMesh(path, filledOptions(0.1f), Precision::FP32, nullptr); },
                          &message),
              ErrorKind::BadInput)
        << path;
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_NE(message.find("PLY"), std::string::npos) << message;
    ++files;
  }
  EXPECT_GE(files, 5);
  const std::string good = tmp("octahedron.ply");
  std::ofstream(good) << "ply\nformat ascii 1.0\ncomment an octahedron\nelement vertex 6\n"
                         "property float x\nproperty float y\nproperty float z\nelement face 8\n"
                         "property list uchar int vertex_indices\nend_header\n"
                         "1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n"
                         "3 0 2 4\n3 2 1 4\n3 1 3 4\n3 3 0 4\n3 2 0 5\n3 1 2 5\n3 3 1 5\n3 0 3 5\n";
  EXPECT_EQ(sdfFromMesh(good, filledOptions(0.1f), Precision::FP32, nullptr).grid().dims.x > 0,
            true);
}

// Meshes the libFuzzer targets found (tests/regression/fuzz/fuzz_mesh_*, named for what they
// did to OpenMesh's readers, the vertex merge or OpenVDB's meshToVolume): each is refused as bad
// input naming the file, or loads and converts on a 16^3 grid, as in the fuzz target.
TEST(MeshRegression, LibFuzzerFindingsAreRefusedOrConvert) {
  int files = 0;
  const auto root = std::filesystem::path(VISOPT_REGRESSION_DIR) / "fuzz";
  for (const auto& target : std::filesystem::directory_iterator(root)) {
    if (target.path().filename().string().rfind("fuzz_mesh_", 0) != 0) continue;
    for (const auto& entry : std::filesystem::directory_iterator(target.path())) {
      const std::string path = entry.path().string();
      MeshSdfOptions options;
      options.filled = false;
      options.shellThickness = 0.05f;
      options.like = GridSpec{glm::ivec3(16)};
      try {
        EXPECT_EQ(sdfFromMesh(path, options, Precision::FP32, nullptr).grid().dims.x, 16) << path;
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadInput) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
      }
      ++files;
    }
  }
  EXPECT_GE(files, 8);
}
