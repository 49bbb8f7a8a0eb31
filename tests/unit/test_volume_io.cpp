// Volume IO: every format reads a small hand-made (or round-tripped) volume with anisotropic
// spacing, a non-zero origin and, where the format has one, a rotated orientation; geometry and
// values are checked against numbers computed by hand. Every kind of bad input gives
// Error(BadInput) naming the file and the problem, and VTK prints nothing. Real datasets (from
// datasets-scripts/fetch_datasets.sh) are checked when present and skipped otherwise.
#include <gtest/gtest.h>
#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "fuzz/smallest_render.h"
#include "nifti_writer.h"
#include "visopt/engine.h"
#include "visopt/error.h"
#include "visopt/memory_ledger.h"
#include "visopt/render_settings.h"
#include "visopt/value_normalization.h"
#include "visopt/volume_io.h"

namespace fs = std::filesystem;
using namespace visopt;

namespace {

// ---- the reference volume --------------------------------------------------------------------
// dims 5 x 4 x 3, spacing 0.5 x 1.25 x 2, origin (10, -20, 30), index axes rotated 90 degrees
// about z: i runs along +y, j along -x, k along +z. Value v(i,j,k) = i + 10 j + 100 k - 50,
// so the range is [-50, 184].
constexpr int NX = 5, NY = 4, NZ = 3, N = NX * NY * NZ;
const glm::vec3 kSpacing(0.5f, 1.25f, 2.f);
const glm::vec3 kOrigin(10.f, -20.f, 30.f);
const glm::mat3 kRotZ(glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1));  // columns

int valueAt(int i, int j, int k) {
  return i + 10 * j + 100 * k - 50;
}
int valueAt(size_t idx) {
  return valueAt(int(idx % NX), int((idx / NX) % NY), int(idx / (NX * NY)));
}

std::string tmpDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::path(VISOPT_TEST_TMP) / "volume_io" / info->name();
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string join(const std::string& dir, const std::string& name) {
  return dir + "/" + name;
}

std::string numbered(const std::string& prefix, int n) {
  std::ostringstream s;
  s << prefix << n;
  return s.str();
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

template <class T>
std::string toBytes(const std::vector<T>& values, bool bigEndian = false) {
  std::string bytes(values.size() * sizeof(T), '\0');
  std::memcpy(bytes.data(), values.data(), bytes.size());
  if (bigEndian != (std::endian::native == std::endian::big))
    for (size_t i = 0; i < values.size(); ++i)
      std::reverse(bytes.begin() + std::ptrdiff_t(i * sizeof(T)),
                   bytes.begin() + std::ptrdiff_t((i + 1) * sizeof(T)));
  return bytes;
}

template <class T>
std::vector<T> referenceValues(int offset = 0) {
  std::vector<T> v(N);
  for (size_t i = 0; i < size_t(N); ++i) v[i] = static_cast<T>(valueAt(i) + offset);
  return v;
}

std::string gzipBytes(const std::string& data, int windowBits) {  // 15: zlib, 31: gzip
  z_stream zs{};
  EXPECT_EQ(deflateInit2(&zs, 6, Z_DEFLATED, windowBits, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&zs, uLong(data.size())) + 64, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  zs.avail_in = uInt(data.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = uInt(out.size());
  EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

std::string sidecarJson(const std::string& type, const std::string& extra = "") {
  std::ostringstream s;
  s << R"({"dims":[5,4,3],"type":")" << type
    << R"(","spacing":[0.5,1.25,2],"origin":[10,-20,30],"direction":[0,-1,0,1,0,0,0,0,1])" << extra
    << "}";
  return s.str();
}

void expectGrid(const GridSpec& g, glm::ivec3 dims, glm::vec3 spacing, glm::vec3 origin,
                const glm::mat3& direction) {
  EXPECT_EQ(g.dims, dims);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(g.spacing[a], spacing[a], 1e-5f) << "spacing axis " << a;
    EXPECT_NEAR(g.origin[a], origin[a], 1e-4f) << "origin axis " << a;
    for (int r = 0; r < 3; ++r)
      EXPECT_NEAR(g.direction[a][r], direction[a][r], 1e-5f)
          << "direction column " << a << " row " << r;
  }
}

void expectReference(const Volume& v, int offset = 0, double tolerance = 1e-3) {
  expectGrid(v.grid(), {NX, NY, NZ}, kSpacing, kOrigin, kRotZ);
  EXPECT_DOUBLE_EQ(v.valueMin, -50.0 + offset);
  EXPECT_DOUBLE_EQ(v.valueMax, 184.0 + offset);
  // Hand-picked voxels: corners and a middle one.
  const int picks[][3] = {{0, 0, 0}, {4, 0, 0}, {0, 3, 0}, {2, 1, 1}, {4, 3, 2}, {1, 2, 2}};
  for (const auto& p : picks) {
    size_t idx = v.grid().linearIndex(p[0], p[1], p[2]);
    EXPECT_NEAR(v.toValue(v.normalized.get(idx)), valueAt(p[0], p[1], p[2]) + offset, tolerance)
        << "voxel " << p[0] << "," << p[1] << "," << p[2];
  }
  // World geometry: voxel (1,0,0) is one x-spacing along +y from the origin.
  glm::vec3 w = v.grid().indexToWorld(glm::vec3(1, 0, 0));
  EXPECT_NEAR(w.y, kOrigin.y + 0.5f, 1e-4f);
  EXPECT_NEAR(w.x, kOrigin.x, 1e-4f);
}

// Expects Error(BadInput) whose message names the file and contains `word`.
void expectBadInput(const std::function<void()>& f, const std::string& path,
                    const std::string& word) {
  ::testing::internal::CaptureStderr();
  ::testing::internal::CaptureStdout();
  std::string msg;
  try {
    f();
    ADD_FAILURE() << "no error for " << path << " (expected '" << word << "')";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput) << e.what();
    msg = e.what();
    EXPECT_NE(msg.find(fs::path(path).filename().string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(word), std::string::npos) << "'" << word << "' not in: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message must be one line: " << msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type for " << path << ": " << e.what();
  }
  std::string err = ::testing::internal::GetCapturedStderr();
  std::string out = ::testing::internal::GetCapturedStdout();
  EXPECT_TRUE(err.empty()) << "printed to stderr: " << err;
  EXPECT_TRUE(out.empty()) << "printed to stdout: " << out;
  if (std::getenv("VISOPT_SHOW_ERRORS")) std::cout << "  message: " << msg << "\n";
}

void expectReadBad(const std::string& path, const std::string& word) {
  expectBadInput([&] { (void)readVolume(path, Precision::FP32); }, path, word);
}

std::string writeRawVolume(const std::string& dir, const std::string& type, const std::string& data,
                           const std::string& extra = "") {
  std::string path = join(dir, "vol.raw");
  writeBytes(path, data);
  writeBytes(path + ".json", sidecarJson(type, extra));
  return path;
}

// A NIfTI-1 header for the test volume's dimensions and spacing.
test_files::NiftiSpec niftiSpec() {
  test_files::NiftiSpec s;
  s.dim[1] = NX, s.dim[2] = NY, s.dim[3] = NZ;
  s.spacing[0] = kSpacing.x, s.spacing[1] = kSpacing.y, s.spacing[2] = kSpacing.z;
  return s;
}

// For a file whose voxel (i,j,k) sits at world = A * (i,j,k) + b, checks that every voxel of
// the loaded volume holds the file value found at its world position.
void expectWorldConsistent(const Volume& v, const glm::mat3& A, const glm::vec3& b, double scale,
                           double shift) {
  glm::mat3 inv = glm::inverse(A);
  for (int k = 0; k < v.grid().dims.z; ++k)
    for (int j = 0; j < v.grid().dims.y; ++j)
      for (int i = 0; i < v.grid().dims.x; ++i) {
        glm::vec3 world = v.grid().indexToWorld(glm::vec3(i, j, k));
        glm::vec3 f = inv * (world - b);
        glm::ivec3 fi(glm::round(f));
        ASSERT_LT(glm::length(f - glm::vec3(fi)), 1e-3f) << "voxel " << i << "," << j << "," << k;
        ASSERT_TRUE(fi.x >= 0 && fi.x < NX && fi.y >= 0 && fi.y < NY && fi.z >= 0 && fi.z < NZ);
        double expected = valueAt(fi.x, fi.y, fi.z) * scale + shift;
        EXPECT_NEAR(v.toValue(v.normalized.get(v.grid().linearIndex(i, j, k))), expected, 1e-3);
      }
}

// ---- a minimal DICOM CT slice (explicit VR little endian), written by hand --------------------
struct DicomWriter {
  std::string body;
  void element(uint16_t group, uint16_t elem, const char vr[2], std::string value) {
    const bool isUid = vr[0] == 'U' && vr[1] == 'I';
    if (value.size() % 2) value.push_back(isUid ? '\0' : ' ');
    body.append(reinterpret_cast<const char*>(&group), 2);
    body.append(reinterpret_cast<const char*>(&elem), 2);
    body.append(vr, 2);
    const std::string v(vr, 2);
    if (v == "OB" || v == "OW") {
      body.append(2, '\0');
      uint32_t len = uint32_t(value.size());
      body.append(reinterpret_cast<const char*>(&len), 4);
    } else {
      uint16_t len = uint16_t(value.size());
      body.append(reinterpret_cast<const char*>(&len), 2);
    }
    body += value;
  }
  void us(uint16_t group, uint16_t elem, uint16_t v) {
    element(group, elem, "US", std::string(reinterpret_cast<const char*>(&v), 2));
  }
};

// Slice k of the reference volume: rows along j, columns along i; position of voxel (0,0,k).
// zJitter (mm) moves the slice's position along the normal, as rounding in the header does.
std::string dicomSlice(int k, double slope, double intercept, float zJitter = 0.f) {
  DicomWriter meta, ds;
  meta.element(0x0002, 0x0001, "OB", std::string("\0\1", 2));
  meta.element(0x0002, 0x0002, "UI", "1.2.840.10008.5.1.4.1.1.2");
  meta.element(0x0002, 0x0003, "UI", "1.2.3.4.5.6." + std::to_string(k + 1));
  meta.element(0x0002, 0x0010, "UI", "1.2.840.10008.1.2.1");
  DicomWriter group;
  uint32_t metaLength = uint32_t(meta.body.size());
  group.element(0x0002, 0x0000, "UL", std::string(reinterpret_cast<const char*>(&metaLength), 4));
  ds.element(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.2");
  ds.element(0x0008, 0x0018, "UI", "1.2.3.4.5.6." + std::to_string(k + 1));
  ds.element(0x0008, 0x0060, "CS", "CT");
  ds.element(0x0018, 0x0050, "DS", "2");
  ds.element(0x0020, 0x000D, "UI", "1.2.3.4.5");
  ds.element(0x0020, 0x000E, "UI", "1.2.3.4.5.6");
  ds.element(0x0020, 0x0013, "IS", std::to_string(k + 1));
  glm::vec3 p = kOrigin + kRotZ[2] * (float(k) * kSpacing.z + zJitter);
  std::ostringstream ipp;
  ipp << p.x << "\\" << p.y << "\\" << p.z;
  ds.element(0x0020, 0x0032, "DS", ipp.str());
  ds.element(0x0020, 0x0037, "DS", "0\\1\\0\\-1\\0\\0");  // row (i) along +y, column (j) along -x
  ds.us(0x0028, 0x0002, 1);
  ds.element(0x0028, 0x0004, "CS", "MONOCHROME2");
  ds.us(0x0028, 0x0010, NY);                      // rows
  ds.us(0x0028, 0x0011, NX);                      // columns
  ds.element(0x0028, 0x0030, "DS", "1.25\\0.5");  // row spacing (j), column spacing (i)
  ds.us(0x0028, 0x0100, 16);
  ds.us(0x0028, 0x0101, 16);
  ds.us(0x0028, 0x0102, 15);
  ds.us(0x0028, 0x0103, 1);
  std::ostringstream b, m;
  b << intercept;
  m << slope;
  ds.element(0x0028, 0x1052, "DS", b.str());
  ds.element(0x0028, 0x1053, "DS", m.str());
  std::vector<int16_t> pixels;
  for (int j = 0; j < NY; ++j)
    for (int i = 0; i < NX; ++i) pixels.push_back(int16_t(valueAt(i, j, k)));
  ds.element(0x7FE0, 0x0010, "OW", toBytes(pixels));
  return std::string(128, '\0') + "DICM" + group.body + meta.body + ds.body;
}

}  // namespace

// =============================================================================================
// Formats
// =============================================================================================

TEST(VolumeIoRaw, Int16LittleEndianWithOrientation) {
  std::string path = writeRawVolume(tmpDir(), "int16", toBytes(referenceValues<int16_t>()));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "int16");
  EXPECT_EQ(v.name, "vol");
  EXPECT_EQ(v.sourcePath, path);
  EXPECT_EQ(v.normalized.name(), "volume");
  expectReference(v);
  // Normalised storage: min -> 0, max -> 1.
  EXPECT_FLOAT_EQ(v.normalized.get(0), 0.f);
  EXPECT_FLOAT_EQ(v.normalized.get(N - 1), 1.f);
}

TEST(VolumeIoRaw, BigEndianTypesHeaderBytesAndSidecarNames) {
  std::string dir = tmpDir();
  // uint16 big endian after a 17-byte header; sidecar named FILE.json (not FILE.raw.json).
  std::string path = join(dir, "be.raw");
  writeBytes(path, std::string(17, 'h') + toBytes(referenceValues<uint16_t>(50), true));
  writeBytes(join(dir, "be.json"), sidecarJson("uint16", R"(,"endian":"big","headerBytes":17)"));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "uint16");
  expectReference(v, 50);

  for (const std::string type : {"int8", "uint8", "int32", "uint32", "float32", "float64"}) {
    std::string sub = join(dir, type);
    fs::create_directories(sub);
    std::string data = type == "int8"      ? toBytes(referenceValues<int8_t>(-60))
                       : type == "uint8"   ? toBytes(referenceValues<uint8_t>(50))
                       : type == "int32"   ? toBytes(referenceValues<int32_t>())
                       : type == "uint32"  ? toBytes(referenceValues<uint32_t>(50))
                       : type == "float32" ? toBytes(referenceValues<float>())
                                           : toBytes(referenceValues<double>());
    int offset = type == "int8" ? -60 : (type == "uint8" || type == "uint32") ? 50 : 0;
    Volume t = readVolume(writeRawVolume(sub, type, data), Precision::FP32);
    EXPECT_EQ(t.scalarType, type);
    expectReference(t, offset);
  }
}

TEST(VolumeIoRaw, Fp16StorageAndLedger) {
  std::string path = writeRawVolume(tmpDir(), "int16", toBytes(referenceValues<int16_t>()));
  MemoryLedger ledger;
  {
    Volume v = readVolume(path, Precision::FP16, &ledger);
    EXPECT_EQ(v.normalized.precision(), Precision::FP16);
    expectReference(v, 0, 0.2);  // fp16 of [0,1]: ~5e-4 relative, 234 units of range
    auto entries = ledger.entries();
    ASSERT_EQ(entries.size(), 1u);
    EXPECT_EQ(entries[0].name, "volume");
    EXPECT_EQ(entries[0].bytes, size_t(N) * 2);
  }
  EXPECT_EQ(ledger.totalBytes(), 0u);
}

TEST(VolumeIoMetaImage, MhaWithTransformMatrix) {
  std::string path = join(tmpDir(), "vol.mha");
  writeBytes(path,
             "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
             "TransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 10 -20 30\n"
             "ElementSpacing = 0.5 1.25 2\nDimSize = 5 4 3\nElementType = MET_SHORT\n"
             "ElementDataFile = LOCAL\n" +
                 toBytes(referenceValues<int16_t>()));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "int16");
  expectReference(v);
}

TEST(VolumeIoMetaImage, MhdDetachedBigEndianAndCompressedMha) {
  std::string dir = tmpDir();
  writeBytes(join(dir, "data.bin"), toBytes(referenceValues<uint16_t>(50), true));
  std::string mhd = join(dir, "vol.mhd");
  writeBytes(mhd,
             "ObjectType = Image\nNDims = 3\nElementByteOrderMSB = True\n"
             "TransformMatrix = 0 1 0 -1 0 0 0 0 1\nOrigin = 10 -20 30\n"
             "ElementSpacing = 0.5 1.25 2\nDimSize = 5 4 3\nElementType = MET_USHORT\n"
             "ElementDataFile = data.bin\n");
  Volume v = readVolume(mhd, Precision::FP32);
  EXPECT_EQ(v.scalarType, "uint16");
  expectReference(v, 50);

  std::string mha = join(dir, "z.mha");
  std::string z = gzipBytes(toBytes(referenceValues<float>()), 15);
  writeBytes(mha, "ObjectType = Image\nNDims = 3\nCompressedData = True\nCompressedDataSize = " +
                      std::to_string(z.size()) +
                      "\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 10 -20 30\n"
                      "ElementSpacing = 0.5 1.25 2\nDimSize = 5 4 3\nElementType = MET_FLOAT\n"
                      "ElementDataFile = LOCAL\n" +
                      z);
  Volume c = readVolume(mha, Precision::FP32);
  EXPECT_EQ(c.scalarType, "float32");
  expectReference(c);
}

TEST(VolumeIoNrrd, AttachedRawBigEndianWithSpaceDirections) {
  std::string path = join(tmpDir(), "vol.nrrd");
  writeBytes(path,
             "NRRD0004\n# made by hand\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
             "sizes: 5 4 3\nspace directions: (0,0.5,0) (-1.25,0,0) (0,0,2)\n"
             "kinds: domain domain domain\nendian: big\nencoding: raw\n"
             "space origin: (10,-20,30)\n\n" +
                 toBytes(referenceValues<int16_t>(), true));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "int16");
  expectReference(v);
}

TEST(VolumeIoNrrd, DetachedGzip) {
  std::string dir = tmpDir();
  writeBytes(join(dir, "vol.raw.gz"), gzipBytes(toBytes(referenceValues<double>()), 31));
  std::string path = join(dir, "vol.nhdr");
  writeBytes(path,
             "NRRD0004\ntype: double\ndimension: 3\nspace dimension: 3\nsizes: 5 4 3\n"
             "space directions: (0,0.5,0) (-1.25,0,0) (0,0,2)\nendian: little\n"
             "encoding: gzip\nspace origin: (10,-20,30)\ndata file: vol.raw.gz\n");
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "float64");
  expectReference(v);
}

TEST(VolumeIoNifti, QformRotationWithRescale) {
  test_files::NiftiSpec s = niftiSpec();
  s.quatern[2] = std::sqrt(0.5f);  // 90 degrees about z: a = d = sqrt(1/2)
  s.qoffset[0] = 10, s.qoffset[1] = -20, s.qoffset[2] = 30;
  s.sclSlope = 2.f, s.sclInter = -3.f;
  std::string path = join(tmpDir(), "vol.nii");
  writeBytes(path, test_files::niftiHeader(s) + toBytes(referenceValues<int16_t>()));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "int16");
  expectGrid(v.grid(), {NX, NY, NZ}, kSpacing, kOrigin, kRotZ);
  EXPECT_DOUBLE_EQ(v.valueMin, -50.0 * 2 - 3);
  EXPECT_DOUBLE_EQ(v.valueMax, 184.0 * 2 - 3);
  EXPECT_NEAR(v.toValue(v.normalized.get(v.grid().linearIndex(2, 1, 1))), valueAt(2, 1, 1) * 2 - 3,
              1e-3);
  glm::mat3 A = kRotZ * glm::mat3(glm::vec3(kSpacing.x, 0, 0), glm::vec3(0, kSpacing.y, 0),
                                  glm::vec3(0, 0, kSpacing.z));
  expectWorldConsistent(v, A, kOrigin, 2.0, -3.0);
}

TEST(VolumeIoNifti, QfacMinusOneKeepsWorldPositions) {
  test_files::NiftiSpec s = niftiSpec();
  s.qfac = -1.f;
  s.quatern[2] = std::sqrt(0.5f);
  s.qoffset[0] = 10, s.qoffset[1] = -20, s.qoffset[2] = 30;
  std::string path = join(tmpDir(), "flip.nii");
  writeBytes(path, test_files::niftiHeader(s) + toBytes(referenceValues<int16_t>()));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.grid().dims, glm::ivec3(NX, NY, NZ));
  // File voxel (i,j,k) lies at R * diag(sx, sy, -sz) * (i,j,k) + qoffset.
  glm::mat3 A = kRotZ * glm::mat3(glm::vec3(kSpacing.x, 0, 0), glm::vec3(0, kSpacing.y, 0),
                                  glm::vec3(0, 0, -kSpacing.z));
  expectWorldConsistent(v, A, kOrigin, 1.0, 0.0);
  EXPECT_NEAR(glm::determinant(v.grid().direction), 1.f, 1e-5f);
}

TEST(VolumeIoNifti, SformWithFlipTakesPrecedence) {
  test_files::NiftiSpec s = niftiSpec();
  s.datatype = 16, s.bitpix = 32;  // float32
  s.qformCode = 0, s.sformCode = 2;
  // x flipped: i runs along -x; j along +y; k along +z.
  float m[3][4] = {{-kSpacing.x, 0, 0, 5}, {0, kSpacing.y, 0, 6}, {0, 0, kSpacing.z, -7}};
  std::memcpy(s.srow, m, sizeof(m));
  std::string path = join(tmpDir(), "sform.nii");
  writeBytes(path, test_files::niftiHeader(s) + toBytes(referenceValues<float>()));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "float32");
  glm::mat3 flipX(glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1));
  glm::mat3 A = flipX * glm::mat3(glm::vec3(kSpacing.x, 0, 0), glm::vec3(0, kSpacing.y, 0),
                                  glm::vec3(0, 0, kSpacing.z));
  expectWorldConsistent(v, A, glm::vec3(5, 6, -7), 1.0, 0.0);
  // VTK keeps index axes right-handed: with a reflecting sform it reverses the slices, so the
  // k axis runs along -z from the last file slice (z = -7 + 2 * 2 = -3).
  glm::mat3 rightHanded(glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, -1));
  expectGrid(v.grid(), {NX, NY, NZ}, kSpacing, glm::vec3(5, 6, -3), rightHanded);
}

TEST(VolumeIoVti, AsciiWithDirection) {
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" "
         "byte_order=\"LittleEndian\">\n<ImageData WholeExtent=\"0 4 0 3 0 2\" "
         "Origin=\"10 -20 30\" Spacing=\"0.5 1.25 2\" Direction=\"0 -1 0 1 0 0 0 0 1\">\n"
         "<Piece Extent=\"0 4 0 3 0 2\">\n<PointData Scalars=\"s\">\n"
         "<DataArray type=\"Int16\" Name=\"s\" format=\"ascii\">\n";
  for (int v : referenceValues<int>()) xml << v << ' ';
  xml << "\n</DataArray>\n</PointData>\n<CellData/>\n</Piece>\n</ImageData>\n</VTKFile>\n";
  std::string path = join(tmpDir(), "vol.vti");
  writeBytes(path, xml.str());
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "int16");
  expectReference(v);
}

TEST(VolumeIoVtkLegacy, AsciiAndBinaryStructuredPoints) {
  std::string dir = tmpDir();
  const std::string head = "# vtk DataFile Version 3.0\nreference\n";
  const std::string geometry =
      "DATASET STRUCTURED_POINTS\nDIMENSIONS 5 4 3\nSPACING 0.5 1.25 2\nORIGIN 10 -20 30\n"
      "POINT_DATA 60\nSCALARS s short 1\nLOOKUP_TABLE default\n";
  std::ostringstream ascii;
  ascii << head << "ASCII\n" << geometry;
  for (int v : referenceValues<int>()) ascii << v << '\n';
  std::string a = join(dir, "ascii.vtk"), b = join(dir, "binary.vtk");
  writeBytes(a, ascii.str());
  writeBytes(b, head + "BINARY\n" + geometry + toBytes(referenceValues<int16_t>(), true) + "\n");
  for (const std::string& path : {a, b}) {
    Volume v = readVolume(path, Precision::FP32);
    EXPECT_EQ(v.scalarType, "int16");
    // Legacy VTK has no orientation: identity.
    expectGrid(v.grid(), {NX, NY, NZ}, kSpacing, kOrigin, glm::mat3(1.f));
    EXPECT_DOUBLE_EQ(v.valueMin, -50.0);
    EXPECT_DOUBLE_EQ(v.valueMax, 184.0);
    EXPECT_NEAR(v.toValue(v.normalized.get(v.grid().linearIndex(2, 1, 1))), valueAt(2, 1, 1), 1e-3);
    EXPECT_NEAR(v.toValue(v.normalized.get(v.grid().linearIndex(4, 3, 2))), 184.0, 1e-3);
  }
}

TEST(VolumeIoInrimage, HeaderPaddedTo256) {
  std::string header =
      "#INRIMAGE-4#{\nXDIM=5\nYDIM=4\nZDIM=3\nVDIM=1\nTYPE=signed fixed\nPIXSIZE=16 bits\n"
      "CPU=decm\nVX=0.5\nVY=1.25\nVZ=2\nXO=10\nYO=-20\nZO=30\n";
  header += std::string(256 - header.size() - 4, '\n') + "##}\n";
  ASSERT_EQ(header.size(), 256u);
  std::string path = join(tmpDir(), "vol.inr");
  writeBytes(path, header + toBytes(referenceValues<int16_t>()));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "int16");
  expectGrid(v.grid(), {NX, NY, NZ}, kSpacing, kOrigin, glm::mat3(1.f));
  EXPECT_DOUBLE_EQ(v.valueMin, -50.0);
  EXPECT_NEAR(v.toValue(v.normalized.get(v.grid().linearIndex(2, 1, 1))), valueAt(2, 1, 1), 1e-3);
}

TEST(VolumeIoPlt, CellEdgeExtents) {
  // Extents are cell edges: x in [9.75, 12.25] over 5 cells -> spacing 0.5, first centre 10.
  std::vector<int32_t> ints = {3, 42, NZ, NY, NX};
  std::vector<float> extents = {29.f, 35.f, -20.625f, -15.625f, 9.75f, 12.25f};
  std::string path = join(tmpDir(), "vol.plt");
  writeBytes(path, toBytes(ints) + toBytes(extents) + toBytes(referenceValues<float>()));
  Volume v = readVolume(path, Precision::FP32);
  EXPECT_EQ(v.scalarType, "float32");
  expectGrid(v.grid(), {NX, NY, NZ}, kSpacing, kOrigin, glm::mat3(1.f));
  EXPECT_DOUBLE_EQ(v.valueMax, 184.0);
  EXPECT_NEAR(v.toValue(v.normalized.get(v.grid().linearIndex(1, 2, 2))), valueAt(1, 2, 2), 1e-3);
}

TEST(VolumeIoDicom, SeriesFolderKeepsPatientGeometry) {
  std::string dir = join(tmpDir(), "series");
  fs::create_directories(dir);
  // Files named against slice order, so the reader must sort by position.
  for (int k = 0; k < NZ; ++k)
    writeBytes(join(dir, numbered("IM", 9 - k) + ".dcm"), dicomSlice(k, 2.0, -3.0));
  Volume v = readVolume(dir, Precision::FP32);
  EXPECT_EQ(v.scalarType, "int16");
  EXPECT_EQ(v.grid().dims, glm::ivec3(NX, NY, NZ));
  EXPECT_DOUBLE_EQ(v.valueMin, -50.0 * 2 - 3);
  EXPECT_DOUBLE_EQ(v.valueMax, 184.0 * 2 - 3);
  glm::mat3 A = kRotZ * glm::mat3(glm::vec3(kSpacing.x, 0, 0), glm::vec3(0, kSpacing.y, 0),
                                  glm::vec3(0, 0, kSpacing.z));
  expectWorldConsistent(v, A, kOrigin, 2.0, -3.0);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(v.grid().spacing[a], kSpacing[a], 1e-5f);
  EXPECT_TRUE(v.warnings.empty());
}

// Slice positions rounded in the headers of a slightly oblique stack (issue 13: an MR series at
// 7 mm with gaps of 6.96-7.07 mm was refused as "uneven slice spacing"): a 20-slice series at
// 2 mm whose gaps alternate between 2.03 and 1.97 mm (the same +-1.5 %) loads on its mean
// spacing, as ITK and Slicer load it, with one warning naming the folder. A missing slice (a
// gap of twice the spacing) is still refused, naming the two slices around it.
TEST(VolumeIoDicom, SpacingJitterIsAcceptedAndAMissingSliceIsNot) {
  const std::string root = tmpDir();
  const int slices = 20;
  const std::string jittered = join(root, "jittered");
  fs::create_directories(jittered);
  for (int k = 0; k < slices; ++k)
    writeBytes(join(jittered, numbered("s", k)), dicomSlice(k, 1, 0, k % 2 ? 0.03f : 0.f));
  const Volume v = readVolume(jittered, Precision::FP32);
  EXPECT_EQ(v.grid().dims.z, slices);
  // The mean spacing: first to last slice over the gaps between them.
  EXPECT_NEAR(v.grid().spacing.z, (float(slices - 1) * kSpacing.z + 0.03f) / float(slices - 1),
              1e-4f);
  ASSERT_EQ(v.warnings.size(), 1u);
  EXPECT_NE(v.warnings[0].find(jittered + ": slice spacing varies from 1.97 to 2.03 mm"),
            std::string::npos)
      << v.warnings[0];
  EXPECT_EQ(probeVolume(jittered).warnings, v.warnings);

  const std::string missing = join(root, "missing");
  fs::create_directories(missing);
  for (int k = 0; k < slices; ++k)
    if (k != 7) writeBytes(join(missing, numbered("s", k)), dicomSlice(k, 1, 0));
  expectReadBad(missing, "s6 and s8 are 4 mm apart where the series' slices are 2 mm apart");
}

TEST(VolumeIoDicom, BadSeries) {
  std::string root = tmpDir();
  std::string dir = join(root, "notdicom");
  fs::create_directories(dir);
  writeBytes(join(dir, "readme.txt"), "nothing to see");
  expectReadBad(dir, "no DICOM files");
  // Two slices at one position.
  std::string dup = join(root, "dup");
  fs::create_directories(dup);
  for (int k = 0; k < NZ; ++k) writeBytes(join(dup, numbered("s", k)), dicomSlice(k, 1, 0));
  writeBytes(join(dup, "s9"), dicomSlice(1, 1, 0));
  expectReadBad(dup, "same position");
  // A slice whose pixel data is cut short.
  std::string cut = join(root, "cut");
  fs::create_directories(cut);
  for (int k = 0; k < NZ; ++k) {
    std::string bytes = dicomSlice(k, 1, 0);
    writeBytes(join(cut, numbered("s", k)), k == 1 ? bytes.substr(0, bytes.size() - 15) : bytes);
  }
  expectReadBad(cut, "cut");
}

// =============================================================================================
// probe, progress, cancellation
// =============================================================================================

TEST(VolumeIoProbe, DescribesWithoutKeeping) {
  std::string path = writeRawVolume(tmpDir(), "int16", toBytes(referenceValues<int16_t>()));
  VolumeInfo info = probeVolume(path);
  EXPECT_EQ(info.path, path);
  EXPECT_EQ(info.format, "raw");
  EXPECT_EQ(info.scalarType, "int16");
  EXPECT_EQ(info.grid.dims, glm::ivec3(NX, NY, NZ));
  EXPECT_DOUBLE_EQ(info.valueMin, -50.0);
  EXPECT_DOUBLE_EQ(info.valueMax, 184.0);
  EXPECT_EQ(info.bytesOnDisk, size_t(N) * 2);
  EXPECT_EQ(info.bytesFp32, size_t(N) * 4);
  EXPECT_EQ(info.bytesFp16, size_t(N) * 2);
}

TEST(VolumeIoProgress, ReportsAndCancels) {
  std::string path = writeRawVolume(tmpDir(), "int16", toBytes(referenceValues<int16_t>()));
  std::vector<std::pair<float, std::string>> calls;
  (void)readVolume(path, Precision::FP32, nullptr, [&](float f, const std::string& stage) {
    calls.emplace_back(f, stage);
    return true;
  });
  ASSERT_GE(calls.size(), 3u);
  for (size_t i = 1; i < calls.size(); ++i) EXPECT_GE(calls[i].first, calls[i - 1].first);
  EXPECT_FLOAT_EQ(calls.back().first, 1.f);
  bool sawHeader = false, sawData = false;
  for (auto& c : calls) {
    sawHeader |= c.second == "header";
    sawData |= c.second == "data";
  }
  EXPECT_TRUE(sawHeader && sawData);

  for (const std::string stop : {"header", "data", "converted"}) {
    try {
      (void)readVolume(path, Precision::FP32, nullptr,
                       [&](float, const std::string& stage) { return stage != stop; });
      ADD_FAILURE() << "not cancelled at " << stop;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Cancelled);
      EXPECT_NE(std::string(e.what()).find("cancelled"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("vol.raw"), std::string::npos);
    }
  }
}

// =============================================================================================
// writeVolume round trips
// =============================================================================================

TEST(VolumeIoWrite, RoundTripsKeepGeometryAndValues) {
  std::string dir = tmpDir();
  Volume src = readVolume(writeRawVolume(dir, "int16", toBytes(referenceValues<int16_t>())),
                          Precision::FP32);
  for (const std::string name : {"out.vti", "out.nii", "out.nii.gz", "out.mha", "out.mhd"}) {
    SCOPED_TRACE(name);
    std::string path = join(dir, name);
    writeVolume(src, path);
    Volume back = readVolume(path, Precision::FP32);
    EXPECT_EQ(back.scalarType, "float32");
    expectReference(back);
  }
  // Atomic writes leave no temporaries behind.
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(VolumeIoWrite, NiftiKeepsAnImproperOrientation) {
  std::string dir = tmpDir();
  std::string raw = join(dir, "flip.raw");
  writeBytes(raw, toBytes(referenceValues<float>()));
  // Index axes i -> +x, j -> +z, k -> +y: a reflection (determinant -1). Formats that keep
  // index axes right-handed (NIfTI through VTK) may reverse an axis; world positions must hold.
  writeBytes(raw + ".json",
             R"({"dims":[5,4,3],"type":"float32","spacing":[0.5,1.25,2],"origin":[1,2,3],)"
             R"("direction":[1,0,0, 0,0,1, 0,1,0]})");
  Volume src = readVolume(raw, Precision::FP32);
  glm::mat3 d(glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0));
  ASSERT_NEAR(glm::determinant(d), -1.f, 1e-6f);
  expectGrid(src.grid(), {NX, NY, NZ}, kSpacing, glm::vec3(1, 2, 3), d);
  for (const std::string name : {"flip.nii", "flip.vti", "flip.mha"}) {
    SCOPED_TRACE(name);
    writeVolume(src, join(dir, name));
    Volume back = readVolume(join(dir, name), Precision::FP32);
    glm::mat3 A = d * glm::mat3(glm::vec3(kSpacing.x, 0, 0), glm::vec3(0, kSpacing.y, 0),
                                glm::vec3(0, 0, kSpacing.z));
    expectWorldConsistent(back, A, glm::vec3(1, 2, 3), 1.0, 0.0);
  }
}

TEST(VolumeIoWrite, FailuresAreReported) {
  std::string dir = tmpDir();
  Volume src = readVolume(writeRawVolume(dir, "int16", toBytes(referenceValues<int16_t>())),
                          Precision::FP32);
  try {
    writeVolume(src, join(dir, "no/such/folder/out.vti"));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out.vti"), std::string::npos) << e.what();
  }
  try {
    writeVolume(src, join(dir, "out.xyz"));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
  }
}

// =============================================================================================
// Bad input
// =============================================================================================

TEST(VolumeIoBadInput, MissingEmptyAndUnknown) {
  std::string dir = tmpDir();
  for (const std::string name : {"none.raw", "none.nii", "none.vti", "none.mha", "none.nrrd",
                                 "none.vtk", "none.inr", "none.plt", "none.nii.gz"})
    expectReadBad(join(dir, name), "not found");
  for (const std::string name : {"empty.raw", "empty.nii", "empty.nii.gz", "empty.vti", "empty.mha",
                                 "empty.nrrd", "empty.vtk", "empty.inr", "empty.plt"}) {
    writeBytes(join(dir, name), "");
    expectReadBad(join(dir, name), "empty");
  }
  writeBytes(join(dir, "vol.xyz"), "data");
  expectReadBad(join(dir, "vol.xyz"), "unknown volume format");
  expectReadBad(join(dir, "missing.xyz"), "not found");
  fs::create_directories(join(dir, "emptyfolder"));
  expectReadBad(join(dir, "emptyfolder"), "no files");
}

TEST(VolumeIoBadInput, TruncatedAndLyingHeaders) {
  std::string dir = tmpDir();
  std::string full = toBytes(referenceValues<int16_t>());
  // Raw shorter than dims * size.
  expectReadBad(writeRawVolume(join(dir, ""), "int16", full.substr(0, full.size() - 3)),
                "truncated");
  // Sidecar whose dims are bigger than the data.
  std::string lie = join(dir, "lie.raw");
  writeBytes(lie, full);
  writeBytes(lie + ".json", R"({"dims":[5,4,30],"type":"int16"})");
  expectReadBad(lie, "truncated");
  // headerBytes past the end.
  std::string skip = join(dir, "skip.raw");
  writeBytes(skip, full);
  writeBytes(skip + ".json", R"({"dims":[5,4,3],"type":"int16","headerBytes":100000})");
  expectReadBad(skip, "truncated");
  // MetaImage header lying about DimSize.
  std::string mha = join(dir, "lie.mha");
  writeBytes(
      mha, "NDims = 3\nDimSize = 5 4 9\nElementType = MET_SHORT\nElementDataFile = LOCAL\n" + full);
  expectReadBad(mha, "truncated");
  // A detached MetaImage whose data file is short or missing: the message names the header the
  // user opened first, then the data file (it named only the data file, which the user never
  // chose).
  const std::string mhd = join(dir, "scan.mhd");
  writeBytes(join(dir, "scan.raw"), full.substr(0, 40));
  writeBytes(mhd,
             "NDims = 3\nDimSize = 5 4 3\nElementType = MET_SHORT\nElementDataFile = scan.raw\n");
  for (const std::string& data : {std::string("scan.raw"), std::string("gone.raw")}) {
    if (data == "gone.raw")
      writeBytes(
          mhd, "NDims = 3\nDimSize = 5 4 3\nElementType = MET_SHORT\nElementDataFile = gone.raw\n");
    try {
      (void)readVolume(mhd, Precision::FP32);
      ADD_FAILURE() << "no error for " << data;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(mhd + ": its data file ", 0), 0u) << msg;
      EXPECT_NE(msg.find(data), std::string::npos) << msg;
      EXPECT_NE(msg.find(data == "gone.raw" ? "file not found" : "truncated"), std::string::npos)
          << msg;
    }
  }
  // Compressed MetaImage cut short.
  std::string z = gzipBytes(full, 15);
  std::string zmha = join(dir, "cut.mha");
  writeBytes(zmha,
             "NDims = 3\nDimSize = 5 4 3\nElementType = MET_SHORT\nCompressedData = True\n"
             "ElementDataFile = LOCAL\n" +
                 z.substr(0, z.size() / 2));
  expectReadBad(zmha, "truncated");
  // NRRD sizes bigger than the data.
  std::string nrrd = join(dir, "lie.nrrd");
  writeBytes(nrrd,
             "NRRD0004\ntype: short\ndimension: 3\nsizes: 5 4 8\nencoding: raw\n"
             "endian: little\n\n" +
                 full);
  expectReadBad(nrrd, "truncated");
  // NIfTI with data cut short.
  test_files::NiftiSpec s = niftiSpec();
  std::string nii = join(dir, "cut.nii");
  writeBytes(nii, test_files::niftiHeader(s) + full.substr(0, full.size() / 2));
  expectReadBad(nii, "cut.nii");
  // NIfTI with the header cut.
  std::string hdr = join(dir, "hdr.nii");
  writeBytes(hdr, test_files::niftiHeader(s).substr(0, 100));
  expectReadBad(hdr, "hdr.nii");
  // .vti cut in the middle of the data.
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\">\n<ImageData "
         "WholeExtent=\"0 4 0 3 0 2\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece Extent=\"0 4 0 "
         "3 0 2\">\n<PointData Scalars=\"s\">\n<DataArray type=\"Int16\" Name=\"s\" "
         "format=\"ascii\">\n1 2 3";
  std::string vti = join(dir, "cut.vti");
  writeBytes(vti, xml.str());
  expectReadBad(vti, "cut.vti");
  // Legacy VTK with fewer values than DIMENSIONS.
  std::string vtk = join(dir, "cut.vtk");
  writeBytes(vtk,
             "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\n"
             "DIMENSIONS 5 4 3\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 60\n"
             "SCALARS s short 1\nLOOKUP_TABLE default\n" +
                 full.substr(0, 20));
  expectReadBad(vtk, "cut.vtk");
  std::string vtkAscii = join(dir, "cuta.vtk");
  writeBytes(vtkAscii,
             "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\n"
             "DIMENSIONS 5 4 3\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 60\n"
             "SCALARS s short 1\nLOOKUP_TABLE default\n1 2 3 4\n");
  expectReadBad(vtkAscii, "cuta.vtk");
  // INRIMAGE and PLT cut short.
  std::string inrHeader =
      "#INRIMAGE-4#{\nXDIM=5\nYDIM=4\nZDIM=3\nVDIM=1\nTYPE=float\n"
      "PIXSIZE=32 bits\nCPU=decm\nVX=1\nVY=1\nVZ=1\n";
  inrHeader += std::string(256 - inrHeader.size() - 4, '\n') + "##}\n";
  writeBytes(join(dir, "cut.inr"), inrHeader + full.substr(0, 10));
  expectReadBad(join(dir, "cut.inr"), "truncated");
  std::vector<int32_t> ints = {3, 42, NZ, NY, NX};
  std::vector<float> ext = {0, 3, 0, 4, 0, 5};
  writeBytes(join(dir, "cut.plt"), toBytes(ints) + toBytes(ext) + full.substr(0, 10));
  expectReadBad(join(dir, "cut.plt"), "truncated");
}

// Compressed data is inflated to the end of its stream: the gzip trailer (CRC-32 and length) is
// checked, data beyond what the header describes is refused, and a header that promises more
// than the compressed bytes can inflate to is refused before anything is allocated (issue 13:
// gzip streams with a bad CRC were accepted; the reader stopped at the bytes it needed).
TEST(VolumeIoBadInput, CompressedStreamsAreCheckedToTheirEnd) {
  const std::string dir = tmpDir();
  const std::string full = toBytes(referenceValues<int16_t>());
  const std::string good = gzipBytes(full, 31);
  auto nrrd = [&](const std::string& name, const std::string& sizes, const std::string& data) {
    const std::string path = join(dir, name);
    writeBytes(path, "NRRD0004\ntype: short\ndimension: 3\nsizes: " + sizes +
                         "\nencoding: gzip\nendian: little\n\n" + data);
    return path;
  };
  EXPECT_NO_THROW((void)readVolume(nrrd("good.nrrd", "5 4 3", good), Precision::FP32));
  std::string badCrc = good;
  badCrc[badCrc.size() - 6] = char(badCrc[badCrc.size() - 6] ^ 0x5a);  // inside the CRC-32
  expectReadBad(nrrd("crc.nrrd", "5 4 3", badCrc), "corrupt compressed data");
  expectReadBad(nrrd("tail.nrrd", "5 4 3", good.substr(0, good.size() - 4)), "truncated");
  expectReadBad(nrrd("more.nrrd", "5 4 3", gzipBytes(full + full.substr(0, 10), 31)), "more than");
  // 1000 x 1000 x 100 shorts (200 MB) from ~100 bytes: refused by the deflate bound.
  expectReadBad(nrrd("huge.nrrd", "1000 1000 100", good), "inflate to at most");

  test_files::NiftiSpec spec = niftiSpec();
  const std::string niiBytes = test_files::niftiHeader(spec) + full;
  const std::string niiGood = gzipBytes(niiBytes, 31);
  writeBytes(join(dir, "good.nii.gz"), niiGood);
  EXPECT_NO_THROW((void)readVolume(join(dir, "good.nii.gz"), Precision::FP32));
  std::string niiCrc = niiGood;
  niiCrc[niiCrc.size() - 6] = char(niiCrc[niiCrc.size() - 6] ^ 0x5a);
  writeBytes(join(dir, "crc.nii.gz"), niiCrc);
  expectReadBad(join(dir, "crc.nii.gz"), "corrupt compressed data");
  writeBytes(join(dir, "cut.nii.gz"), gzipBytes(niiBytes.substr(0, niiBytes.size() - 20), 31));
  expectReadBad(join(dir, "cut.nii.gz"), "once inflated");
}

TEST(VolumeIoBadInput, AbsurdDimensionsRefusedBeforeAllocation) {
  std::string dir = tmpDir();
  std::string data = toBytes(referenceValues<int16_t>());
  auto sidecar = [&](const std::string& name, const std::string& json) {
    std::string path = join(dir, name);
    writeBytes(path, data);
    writeBytes(path + ".json", json);
    return path;
  };
  expectReadBad(sidecar("zero.raw", R"({"dims":[5,0,3],"type":"int16"})"), "invalid dimensions");
  expectReadBad(sidecar("neg.raw", R"({"dims":[5,-4,3],"type":"int16"})"), "invalid dimensions");
  expectReadBad(
      sidecar("over.raw", R"({"dims":[2000000000,2000000000,2000000000],"type":"int16"})"),
      "overflow");
  expectReadBad(sidecar("axis.raw", R"({"dims":[5000000000,1,1],"type":"int16"})"), "overflow");
  // 1e13 voxels: no overflow, but 40 TB as fp32.
  expectReadBad(sidecar("huge.raw", R"({"dims":[100000,100000,1000],"type":"uint8"})"),
                "available memory");
  // The same checks guard the other header formats.
  std::string mha = join(dir, "huge.mha");
  writeBytes(mha,
             "NDims = 3\nDimSize = 100000 100000 1000\nElementType = MET_UCHAR\n"
             "ElementDataFile = LOCAL\nxx");
  expectReadBad(mha, "available memory");
  std::string nrrd = join(dir, "zero.nrrd");
  writeBytes(nrrd, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 0 3\nencoding: raw\n\nxx");
  expectReadBad(nrrd, "invalid dimensions");
  std::ostringstream vti;
  vti << "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\">\n<ImageData "
         "WholeExtent=\"0 99999 0 99999 0 999\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece "
         "Extent=\"0 99999 0 99999 0 999\">\n<PointData Scalars=\"s\">\n<DataArray type=\"UInt8\" "
         "Name=\"s\" format=\"ascii\">\n1 2 3\n</DataArray>\n</PointData>\n</Piece>\n"
         "</ImageData>\n</VTKFile>\n";
  writeBytes(join(dir, "huge.vti"), vti.str());
  expectReadBad(join(dir, "huge.vti"), "available memory");
}

TEST(VolumeIoBadInput, TypesComponentsAndValues) {
  std::string dir = tmpDir();
  std::string data = toBytes(referenceValues<int16_t>());
  std::string path = writeRawVolume(dir, "complex64", data);
  expectReadBad(path, "unsupported scalar type");
  std::string mha = join(dir, "str.mha");
  writeBytes(
      mha,
      "NDims = 3\nDimSize = 5 4 3\nElementType = MET_STRING\nElementDataFile = LOCAL\n" + data);
  expectReadBad(mha, "unsupported ElementType");
  std::string rgb = join(dir, "rgb.mha");
  writeBytes(rgb,
             "NDims = 3\nDimSize = 5 4 1\nElementNumberOfChannels = 3\nElementType = "
             "MET_UCHAR\nElementDataFile = LOCAL\n" +
                 std::string(60, 'x'));
  expectReadBad(rgb, "multi-component");
  std::string vec = join(dir, "vec.nrrd");
  writeBytes(vec,
             "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 3 5 4 1\nkinds: vector domain "
             "domain domain\nencoding: raw\n\n" +
                 std::string(60, 'x'));
  expectReadBad(vec, "multi-component");
  std::ostringstream vti;
  vti << "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\">\n<ImageData "
         "WholeExtent=\"0 1 0 1 0 0\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n<Piece "
         "Extent=\"0 1 0 1 0 0\">\n<PointData Vectors=\"v\">\n<DataArray type=\"Float32\" "
         "Name=\"v\" NumberOfComponents=\"3\" format=\"ascii\">\n1 2 3 4 5 6 7 8 9 10 11 12\n"
         "</DataArray>\n</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n";
  writeBytes(join(dir, "vec.vti"), vti.str());
  expectReadBad(join(dir, "vec.vti"), "multi-component");
  // NaN and Inf values: refused, with their count.
  std::vector<float> f = referenceValues<float>();
  f[3] = std::numeric_limits<float>::quiet_NaN();
  f[7] = std::numeric_limits<float>::infinity();
  f[11] = -std::numeric_limits<float>::infinity();
  std::string nanDir = join(dir, "nan");
  fs::create_directories(nanDir);
  std::string nan = writeRawVolume(nanDir, "float32", toBytes(f));
  expectReadBad(nan, "3 of 60 values are NaN or Inf");
  expectBadInput([&] { (void)probeVolume(nan); }, nan, "NaN or Inf");
  std::string nanMha = join(dir, "nan.mha");
  writeBytes(nanMha,
             "NDims = 3\nDimSize = 5 4 3\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n" +
                 toBytes(f));
  expectReadBad(nanMha, "NaN or Inf");
}

TEST(VolumeIoBadInput, GeometryAndSidecarProblems) {
  std::string dir = tmpDir();
  std::string data = toBytes(referenceValues<int16_t>());
  auto sidecar = [&](const std::string& name, const std::string& json) {
    std::string path = join(dir, name);
    writeBytes(path, data);
    writeBytes(path + ".json", json);
    return path;
  };
  expectReadBad(sidecar("sp0.raw", R"({"dims":[5,4,3],"type":"int16","spacing":[1,0,1]})"),
                "invalid spacing");
  expectReadBad(sidecar("spn.raw", R"({"dims":[5,4,3],"type":"int16","spacing":[1,-2,1]})"),
                "invalid spacing");
  std::string mha = join(dir, "nan.mha");
  writeBytes(mha,
             "NDims = 3\nDimSize = 5 4 3\nElementSpacing = nan 1 1\nElementType = "
             "MET_SHORT\nElementDataFile = LOCAL\n" +
                 data);
  expectReadBad(mha, "invalid spacing");
  // Finite but beyond what fp32 geometry can carry (issue 13: renders of such files, which the
  // readers accepted, segfaulted): spacings of 1e30 and 1e-30, an origin of -3e38, and a spacing
  // ratio of 1e20 (a ray-march step of a fraction of the smallest would never cross the box).
  expectReadBad(sidecar("huge.raw", R"({"dims":[5,4,3],"type":"int16","spacing":[1e30,1,1]})"),
                "out of range");
  expectReadBad(sidecar("tiny.raw", R"({"dims":[5,4,3],"type":"int16","spacing":[1e-30,1,1]})"),
                "out of range");
  expectReadBad(sidecar("far.raw", R"({"dims":[5,4,3],"type":"int16","origin":[0,-3e38,0]})"),
                "out of range");
  expectReadBad(sidecar("flat.raw", R"({"dims":[5,4,3],"type":"int16","spacing":[1e-5,1,10]})"),
                "too anisotropic");
  // A clinical stack (0.3 mm pixels, 10 mm slices) is fine.
  EXPECT_NO_THROW((void)readVolume(
      sidecar("mr.raw", R"({"dims":[5,4,3],"type":"int16","spacing":[0.3,0.3,10]})"),
      Precision::FP32));
  expectReadBad(
      sidecar("shear.raw", R"({"dims":[5,4,3],"type":"int16","direction":[1,0.5,0,0,1,0,0,0,1]})"),
      "orthonormal");
  expectReadBad(sidecar("bad.raw", R"({"dims":[5,4,3],"type":"int16",)"), "invalid JSON");
  expectReadBad(sidecar("nodims.raw", R"({"type":"int16"})"), "dims");
  expectReadBad(sidecar("comp.raw", R"({"dims":[5,4,1],"type":"int16","components":3})"),
                "multi-component");
  std::string lonely = join(dir, "lonely.raw");
  writeBytes(lonely, data);
  expectReadBad(lonely, "sidecar");
  // Garbage where a header should be.
  for (const std::string name : {"junk.nii", "junk.vti", "junk.vtk", "junk.mha", "junk.nrrd",
                                 "junk.inr", "junk.plt", "junk.nii.gz"}) {
    writeBytes(join(dir, name), std::string(400, '\x07') + "garbage");
    expectReadBad(join(dir, name), name);
  }
}

// =============================================================================================
// Real data (datasets-scripts/fetch_datasets.sh)
// =============================================================================================

namespace {
std::string dataFile(const std::string& name) {
  return std::string(VISOPT_DATA_DIR) + "/" + name;
}
#define REQUIRE_DATA(name)         \
  if (!fs::exists(dataFile(name))) \
  GTEST_SKIP() << dataFile(name) << " absent; run datasets-scripts/fetch_datasets.sh to fetch it"
}  // namespace

TEST(VolumeIoRealData, Cranium) {
  REQUIRE_DATA("Cranium.raw");
  Volume v = readVolume(dataFile("Cranium.raw"), Precision::FP16);
  EXPECT_EQ(v.scalarType, "int16");
  expectGrid(v.grid(), {256, 256, 108}, {0.9570312f, 0.9570312f, 1.5f}, glm::vec3(0.f),
             glm::mat3(1.f));
  EXPECT_DOUBLE_EQ(v.valueMin, -1024.0);
  EXPECT_GT(v.valueMax, 2900.0);
  EXPECT_LT(v.valueMax, 3100.0);
}

TEST(VolumeIoRealData, SkullInrimageAndRaw) {
  REQUIRE_DATA("skull_2.9.inr");
  VolumeInfo inr = probeVolume(dataFile("skull_2.9.inr"));
  EXPECT_EQ(inr.format, "inrimage");
  EXPECT_EQ(inr.scalarType, "float32");
  expectGrid(inr.grid, {64, 64, 64}, {3.94305f, 3.94305f, 3.65079f}, glm::vec3(0.f),
             glm::mat3(1.f));
  EXPECT_LT(inr.valueMin, 2.9);  // isovalue 2.9 lies inside the range
  EXPECT_GT(inr.valueMax, 2.9);
  REQUIRE_DATA("skull_2.9.raw");
  VolumeInfo raw = probeVolume(dataFile("skull_2.9.raw"));
  EXPECT_EQ(raw.grid, inr.grid);
  EXPECT_DOUBLE_EQ(raw.valueMin, inr.valueMin);
  EXPECT_DOUBLE_EQ(raw.valueMax, inr.valueMax);
}

TEST(VolumeIoRealData, Brainsmall) {
  REQUIRE_DATA("brainsmall.raw");
  VolumeInfo info = probeVolume(dataFile("brainsmall.raw"));
  EXPECT_EQ(info.scalarType, "uint8");
  EXPECT_EQ(info.grid.dims, glm::ivec3(128, 128, 84));
  EXPECT_GE(info.valueMin, 0.0);
  EXPECT_LE(info.valueMax, 255.0);
  EXPECT_GT(info.valueMax, 100.0);
}

TEST(VolumeIoRealData, Water) {
  REQUIRE_DATA("nAChR_M2_water.plt");
  VolumeInfo plt = probeVolume(dataFile("nAChR_M2_water.plt"));
  EXPECT_EQ(plt.format, "plt");
  expectGrid(plt.grid, {46, 46, 78}, glm::vec3(1.f), {0.5995f, 0.5995f, 0.592f}, glm::mat3(1.f));
  EXPECT_GE(plt.valueMin, 0.0);  // a density
  EXPECT_GT(plt.valueMax, plt.valueMin);
  REQUIRE_DATA("water.raw");
  VolumeInfo raw = probeVolume(dataFile("water.raw"));
  EXPECT_EQ(raw.grid.dims, plt.grid.dims);
  EXPECT_DOUBLE_EQ(raw.valueMax, plt.valueMax);
}

// Files that crashed a reader when mutated from valid ones (tests/regression/volumes, each named
// for what is wrong in it): each is refused as bad input naming the file, by probeVolume (what
// `visopt info` runs) and by readVolume. vtkNIFTIImageReader segfaulted on a datatype it does not
// know with bitpix 0 before the NIfTI header was checked ahead of it.
TEST(VolumeIoRegression, FuzzFindingsAreRefusedCleanly) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(VISOPT_REGRESSION_DIR) / "volumes")) {
    const std::string path = entry.path().string();
    expectBadInput([&] { (void)probeVolume(path); }, path, "");
    expectReadBad(path, "");
    ++files;
  }
  EXPECT_GE(files, 2);
}

// Inputs the libFuzzer targets found (tests/regression/fuzz/fuzz_volume_*, named for what they
// did: crashed VTK's DICOM or legacy parser, overflowed a conversion, leaked, or were accepted
// and then crashed the renderer). In this build too, each is refused as bad input naming the
// file, or read and rendered.
TEST(VolumeIoRegression, LibFuzzerFindingsAreRefusedOrRender) {
  int files = 0;
  const fs::path root = fs::path(VISOPT_REGRESSION_DIR) / "fuzz";
  for (const auto& target : fs::directory_iterator(root)) {
    const std::string name = target.path().filename().string();
    if (name.rfind("fuzz_volume_", 0) != 0) continue;
    for (const auto& entry : fs::directory_iterator(target.path())) {
      std::string path = entry.path().string();
      if (name == "fuzz_volume_dicom") {  // the target's input is the one slice of a series
        const std::string folder = join(tmpDir(), "series-" + entry.path().stem().string());
        fs::create_directories(folder);
        fs::copy_file(path, join(folder, "slice.dcm"), fs::copy_options::overwrite_existing);
        path = folder;
      }
      try {
        EXPECT_EQ(fuzz::renderSmallest(readVolume(path, Precision::FP32)).width, 16) << path;
      } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadInput) << path << ": " << e.what();
        EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
      }
      ++files;
    }
  }
  EXPECT_GE(files, 10);
}

// The normalisation (value - lo) / (hi - lo), clamped, against its closed form on ranges where
// the formula as written breaks in double: a subnormal span, whose reciprocal overflows (0 * inf
// was NaN: the fuzz finding float64-range-overflows.inr), and a span that itself overflows.
TEST(ValueNormalization, MatchesTheClosedFormOnEveryFiniteRange) {
  const ValueNormalization plain(-100.0, 300.0);
  EXPECT_FLOAT_EQ(plain(-100.0), 0.f);
  EXPECT_FLOAT_EQ(plain(0.0), 0.25f);
  EXPECT_FLOAT_EQ(plain(300.0), 1.f);
  EXPECT_FLOAT_EQ(plain(-1e9), 0.f);  // clamped below and above
  EXPECT_FLOAT_EQ(plain(1e9), 1.f);

  const double tiny = 4 * std::numeric_limits<double>::denorm_min();
  ASSERT_FALSE(std::isfinite(1.0 / tiny));
  const ValueNormalization subnormal(0.0, tiny);
  EXPECT_FLOAT_EQ(subnormal(0.0), 0.f);
  EXPECT_FLOAT_EQ(subnormal(tiny / 2), 0.5f);
  EXPECT_FLOAT_EQ(subnormal(tiny), 1.f);

  const double big = std::numeric_limits<double>::max();
  ASSERT_FALSE(std::isfinite(big - -big));
  const ValueNormalization huge(-big, big);
  EXPECT_FLOAT_EQ(huge(-big), 0.f);
  EXPECT_FLOAT_EQ(huge(0.0), 0.5f);
  EXPECT_FLOAT_EQ(huge(big / 2), 0.75f);
  EXPECT_FLOAT_EQ(huge(big), 1.f);

  EXPECT_EQ(plain(std::nan("")), 0.f);  // never a NaN in a field
  EXPECT_EQ(huge(std::nan("")), 0.f);
  EXPECT_EQ(ValueNormalization(5.0, 5.0)(5.0), 0.f);  // one value: no range to spread over
}
