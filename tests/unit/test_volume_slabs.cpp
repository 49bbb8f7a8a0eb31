// VolumeSlabReader: every supported format (raw little and big endian, int16 and float32; .mha;
// .mhd + .raw; NIfTI-1 with a rescale, qfac -1, a reflecting sform, big endian), written to a
// temporary folder with odd dims, read in several slab splits: the values, normalised exactly
// as volume_io.cpp does, equal readVolume's field bit for bit, and grid() equals its grid. Bad
// input: truncated data (only the slabs past the end fail), absurd dims, compressed and
// unsupported formats, NaN, and slice ranges outside the volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nifti_writer.h"
#include "visopt/error.h"
#include "visopt/volume_io.h"
#include "visopt/volume_slabs.h"

namespace fs = std::filesystem;
using namespace visopt;

namespace {

constexpr int NX = 7, NY = 5, NZ = 9, N = NX * NY * NZ;

// Stored values: varied, signed, not monotonic along any axis.
double storedAt(int i, int j, int k) {
  return double((i * 37 + j * 101 + k * 59 + i * j * k) % 211) - 100.0;
}

std::string tmpDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::path(VISOPT_TEST_TMP) / "volume_slabs" / info->name();
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string join(const std::string& dir, const std::string& name) {
  return dir + "/" + name;
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

template <class T>
void append(std::string& bytes, T value, bool bigEndian) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  bytes.append(b, sizeof(T));
}

// The reference volume as T, x fastest; `scale` makes float data non-integral. Unsigned types
// hold storedAt + 100 (>= 0).
template <class T>
std::string volumeBytes(bool bigEndian, double scale = 1.0) {
  const double shift = std::is_unsigned_v<T> ? 100.0 : 0.0;
  std::string bytes;
  for (int k = 0; k < NZ; ++k)
    for (int j = 0; j < NY; ++j)
      for (int i = 0; i < NX; ++i)
        append(bytes, static_cast<T>((storedAt(i, j, k) + shift) * scale), bigEndian);
  return bytes;
}

std::string writeRaw(const std::string& dir, const std::string& name, const std::string& type,
                     const std::string& data, const std::string& extra = "") {
  const std::string path = join(dir, name);
  writeBytes(path, data);
  std::ostringstream json;
  json << R"({"dims":[)" << NX << "," << NY << "," << NZ << R"(],"type":")" << type
       << R"(","spacing":[0.5,1.25,2],"origin":[10,-20,30],"direction":[0,-1,0,1,0,0,0,0,1])"
       << extra << "}";
  writeBytes(path + ".json", json.str());
  return path;
}

// A NIfTI-1 header for the test volume's dimensions and spacing.
test_files::NiftiSpec niftiSpec() {
  test_files::NiftiSpec s;
  s.dim[1] = NX, s.dim[2] = NY, s.dim[3] = NZ;
  s.spacing[0] = 0.5f, s.spacing[1] = 1.25f, s.spacing[2] = 2.f;
  return s;
}

using Split = std::vector<std::pair<int, int>>;

std::vector<Split> splits() {
  Split singles;
  for (int k = 0; k < NZ; ++k) singles.emplace_back(k, k + 1);
  return {{{0, NZ}}, {{0, 4}, {4, NZ}}, {{0, 2}, {2, 7}, {7, NZ}}, singles};
}

// Reads `path` slab by slab in every split and compares with readVolume.
void expectSlabsMatchReadVolume(const std::string& path, const std::string& format) {
  SCOPED_TRACE(path);
  const Volume volume = readVolume(path, Precision::FP32);
  const VolumeSlabReader reader(path);
  EXPECT_EQ(reader.path(), path);
  EXPECT_EQ(reader.format(), format);
  EXPECT_EQ(reader.grid(), volume.grid());
  EXPECT_EQ(reader.warnings(), volume.warnings);
  ASSERT_EQ(reader.grid().dims, glm::ivec3(NX, NY, NZ));
  for (const Split& split : splits()) {
    SCOPED_TRACE(testing::Message() << split.size() << " slabs");
    std::vector<double> values;
    for (auto [zBegin, zEnd] : split) {
      std::vector<double> slab = reader.readSlices(zBegin, zEnd);
      ASSERT_EQ(slab.size(), size_t(zEnd - zBegin) * NX * NY);
      values.insert(values.end(), slab.begin(), slab.end());
    }
    ASSERT_EQ(values.size(), size_t(N));
    const double lo = *std::min_element(values.begin(), values.end());
    const double hi = *std::max_element(values.begin(), values.end());
    EXPECT_EQ(lo, volume.valueMin);
    EXPECT_EQ(hi, volume.valueMax);
    // normalizeInto's expression.
    const double scale = hi > lo ? 1.0 / (hi - lo) : 0.0;
    size_t mismatches = 0;
    for (size_t i = 0; i < values.size(); ++i) {
      const float t = float(std::clamp((values[i] - lo) * scale, 0.0, 1.0));
      mismatches += std::bit_cast<uint32_t>(t) != std::bit_cast<uint32_t>(volume.normalized.get(i));
    }
    EXPECT_EQ(mismatches, 0u);
  }
}

// Expects Error(kind) whose message names `file` and contains `word`.
void expectError(const std::function<void()>& f, ErrorKind kind, const std::string& file,
                 const std::string& word) {
  try {
    f();
    ADD_FAILURE() << "no error (expected '" << word << "' naming " << file << ")";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.kind(), kind) << msg;
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_NE(msg.find(word), std::string::npos) << "'" << word << "' not in: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
  }
}

void expectBadInput(const std::function<void()>& f, const std::string& file,
                    const std::string& word) {
  expectError(f, ErrorKind::BadInput, file, word);
}

}  // namespace

// =============================================================================================
// Values and geometry equal readVolume's
// =============================================================================================

TEST(VolumeSlabs, RawLittleAndBigEndianInt16AndFloat32) {
  const std::string dir = tmpDir();
  expectSlabsMatchReadVolume(writeRaw(dir, "le16.raw", "int16", volumeBytes<int16_t>(false)),
                             "raw");
  expectSlabsMatchReadVolume(
      writeRaw(dir, "be16.raw", "int16", volumeBytes<int16_t>(true), R"(,"endian":"big")"), "raw");
  expectSlabsMatchReadVolume(writeRaw(dir, "le32.raw", "float32", volumeBytes<float>(false, 0.173)),
                             "raw");
  expectSlabsMatchReadVolume(
      writeRaw(dir, "be32.raw", "float32", volumeBytes<float>(true, 0.173), R"(,"endian":"big")"),
      "raw");
  // A header before the data.
  expectSlabsMatchReadVolume(
      writeRaw(dir, "skip.raw", "int16", std::string(13, 'h') + volumeBytes<int16_t>(false),
               R"(,"headerBytes":13)"),
      "raw");
  // The values themselves: stored values at their (i, j, k).
  const VolumeSlabReader reader(join(dir, "be16.raw"));
  const std::vector<double> slab = reader.readSlices(3, 5);
  for (int k = 3; k < 5; ++k)
    for (int j = 0; j < NY; ++j)
      for (int i = 0; i < NX; ++i)
        ASSERT_EQ(slab[size_t(((k - 3) * NY + j) * NX + i)], storedAt(i, j, k));
}

TEST(VolumeSlabs, MetaImageMhaAndMhd) {
  const std::string dir = tmpDir();
  std::ostringstream dims;
  dims << "NDims = 3\nDimSize = " << NX << " " << NY << " " << NZ << "\n";
  const std::string geometry =
      "ElementSpacing = 0.5 1.25 2\nOffset = 10 -20 30\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\n";
  const std::string mha = join(dir, "vol.mha");
  writeBytes(mha, dims.str() + geometry + "ElementType = MET_SHORT\nElementDataFile = LOCAL\n" +
                      volumeBytes<int16_t>(false));
  expectSlabsMatchReadVolume(mha, "metaimage");

  const std::string mhd = join(dir, "vol.mhd");
  writeBytes(join(dir, "vol.data"), std::string(16, 'h') + volumeBytes<float>(true, 0.37));
  writeBytes(mhd, dims.str() + geometry +
                      "ElementType = MET_FLOAT\nBinaryDataByteOrderMSB = True\nHeaderSize = 16\n"
                      "ElementDataFile = vol.data\n");
  expectSlabsMatchReadVolume(mhd, "metaimage");

  // HeaderSize = -1: the data ends the file.
  const std::string tail = join(dir, "tail.mhd");
  writeBytes(join(dir, "tail.data"), std::string(21, 'h') + volumeBytes<uint16_t>(false));
  writeBytes(tail, dims.str() +
                       "ElementType = MET_USHORT\nHeaderSize = -1\n"
                       "ElementDataFile = tail.data\n");
  expectSlabsMatchReadVolume(tail, "metaimage");
}

TEST(VolumeSlabs, NiftiRescaleQfacSformAndByteOrder) {
  const std::string dir = tmpDir();
  {  // qform rotation, non-identity scl_slope / scl_inter
    test_files::NiftiSpec s = niftiSpec();
    s.quatern[2] = std::sqrt(0.5f);
    s.qoffset[0] = 10, s.qoffset[1] = -20, s.qoffset[2] = 30;
    s.sclSlope = 0.37f, s.sclInter = -12.5f;
    const std::string path = join(dir, "rescale.nii");
    writeBytes(path, test_files::niftiHeader(s) + volumeBytes<int16_t>(false));
    expectSlabsMatchReadVolume(path, "nifti");
    const VolumeSlabReader reader(path);
    EXPECT_EQ(reader.readSlices(2, 3)[size_t(1 * NX + 4)],
              storedAt(4, 1, 2) * double(0.37f) + double(-12.5f));
  }
  {  // qfac -1: VTK reverses the slices; so must the slabs
    test_files::NiftiSpec s = niftiSpec();
    s.qfac = -1.f;
    s.quatern[2] = std::sqrt(0.5f);
    s.qoffset[0] = 10, s.qoffset[1] = -20, s.qoffset[2] = 30;
    s.sclSlope = 2.f, s.sclInter = 3.f;
    const std::string path = join(dir, "qfac.nii");
    writeBytes(path, test_files::niftiHeader(s) + volumeBytes<int16_t>(false));
    expectSlabsMatchReadVolume(path, "nifti");
    const VolumeSlabReader reader(path);
    EXPECT_EQ(reader.readSlices(0, 1)[0], storedAt(0, 0, NZ - 1) * 2.0 + 3.0);
  }
  {  // a reflecting sform (float32): reversed slices too
    test_files::NiftiSpec s = niftiSpec();
    s.datatype = 16, s.bitpix = 32;
    s.qformCode = 0, s.sformCode = 2;
    float m[3][4] = {{-0.5f, 0, 0, 5}, {0, 1.25f, 0, 6}, {0, 0, 2.f, -7}};
    std::memcpy(s.srow, m, sizeof(m));
    const std::string path = join(dir, "sform.nii");
    writeBytes(path, test_files::niftiHeader(s) + volumeBytes<float>(false, 0.173));
    expectSlabsMatchReadVolume(path, "nifti");
  }
  {  // big endian, uint16, with a rescale
    test_files::NiftiSpec s = niftiSpec();
    s.bigEndian = true;
    s.datatype = 512;
    s.sclSlope = -1.5f, s.sclInter = 100.f;
    const std::string path = join(dir, "big.nii");
    writeBytes(path, test_files::niftiHeader(s) + volumeBytes<uint16_t>(true));
    expectSlabsMatchReadVolume(path, "nifti");
  }
  {  // a time series: the first frame, as readVolume
    test_files::NiftiSpec s = niftiSpec();
    s.dim[0] = 4, s.dim[4] = 2;
    const std::string path = join(dir, "frames.nii");
    writeBytes(path, test_files::niftiHeader(s) + volumeBytes<int16_t>(false) +
                         volumeBytes<int16_t>(true));
    expectSlabsMatchReadVolume(path, "nifti");
  }
}

// =============================================================================================
// Bad input
// =============================================================================================

TEST(VolumeSlabs, TruncatedDataFailsOnlyTheSlabsPastTheEnd) {
  const std::string dir = tmpDir();
  const std::string full = volumeBytes<int16_t>(false);
  const std::string cut = full.substr(0, full.size() - 10);  // slice 8 is short
  const std::string complete = writeRaw(dir, "full.raw", "int16", full);
  const VolumeSlabReader reference(complete);
  std::ostringstream dims;
  dims << "NDims = 3\nDimSize = " << NX << " " << NY << " " << NZ << "\n";
  test_files::NiftiSpec nifti = niftiSpec();
  writeBytes(join(dir, "cut.nii"), test_files::niftiHeader(nifti) + cut);
  writeBytes(join(dir, "cut.mha"),
             dims.str() + "ElementType = MET_SHORT\nElementDataFile = LOCAL\n" + cut);
  writeBytes(join(dir, "cut.data"), cut);
  writeBytes(join(dir, "cut.mhd"),
             dims.str() + "ElementType = MET_SHORT\nElementDataFile = cut.data\n");
  const std::string names[] = {writeRaw(dir, "cut.raw", "int16", cut), join(dir, "cut.nii"),
                               join(dir, "cut.mha"), join(dir, "cut.mhd")};
  for (const std::string& path : names) {
    SCOPED_TRACE(path);
    const VolumeSlabReader reader(path);  // the header alone is fine
    EXPECT_EQ(reader.readSlices(0, NZ - 1), reference.readSlices(0, NZ - 1));
    EXPECT_EQ(reader.readSlices(5, 6), reference.readSlices(5, 6));
    for (auto [zBegin, zEnd] : {std::pair{NZ - 1, NZ}, std::pair{4, NZ}})
      expectBadInput([&] { (void)reader.readSlices(zBegin, zEnd); }, path, "truncated");
  }
  // A detached data file: the message names the header opened, then the data file.
  try {
    (void)VolumeSlabReader(join(dir, "cut.mhd")).readSlices(0, NZ);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(join(dir, "cut.mhd") + ": its data file ", 0), 0u) << msg;
    EXPECT_NE(msg.find("cut.data"), std::string::npos) << msg;
  }
  // A missing data file is reported when a slab needs it, naming it.
  writeBytes(join(dir, "gone.mhd"),
             dims.str() + "ElementType = MET_SHORT\nElementDataFile = gone.data\n");
  const VolumeSlabReader gone(join(dir, "gone.mhd"));
  expectBadInput([&] { (void)gone.readSlices(0, 1); }, "gone.data", "file not found");
}

TEST(VolumeSlabs, AbsurdHeadersAreRefused) {
  const std::string dir = tmpDir();
  const std::string data = volumeBytes<int16_t>(false);
  auto sidecar = [&](const std::string& name, const std::string& json) {
    const std::string path = join(dir, name);
    writeBytes(path, data);
    writeBytes(path + ".json", json);
    return path;
  };
  auto open = [](const std::string& path) { return [path] { (void)VolumeSlabReader(path); }; };
  expectBadInput(
      open(sidecar("over.raw", R"({"dims":[2000000000,2000000000,2000000000],"type":"int16"})")),
      "over.raw", "overflow");
  expectBadInput(open(sidecar("axis.raw", R"({"dims":[5000000000,1,1],"type":"int16"})")),
                 "axis.raw", "overflow");
  expectBadInput(open(sidecar("zero.raw", R"({"dims":[5,0,3],"type":"int16"})")), "zero.raw",
                 "invalid dimensions");
  expectBadInput(open(sidecar("type.raw", R"({"dims":[7,5,9],"type":"complex64"})")), "type.raw",
                 "unsupported scalar type");
  const std::string mha = join(dir, "axis.mha");
  writeBytes(mha,
             "NDims = 3\nDimSize = 3000000000 2 2\nElementType = MET_UCHAR\n"
             "ElementDataFile = LOCAL\nxx");
  expectBadInput(open(mha), "axis.mha", "too large");
  test_files::NiftiSpec s = niftiSpec();
  s.dim[2] = -5;
  writeBytes(join(dir, "neg.nii"), test_files::niftiHeader(s) + data);
  expectBadInput(open(join(dir, "neg.nii")), "neg.nii", "dim[2]");

  // 1e13 voxels: more than memory holds, which a slab reader does not need, but the data is not
  // in the file: the first slab is refused before anything is allocated for it.
  const std::string huge = sidecar("huge.raw", R"({"dims":[100000,100000,1000],"type":"uint8"})");
  const VolumeSlabReader reader(huge);
  EXPECT_EQ(reader.grid().dims, glm::ivec3(100000, 100000, 1000));
  expectBadInput([&] { (void)reader.readSlices(0, 1); }, "huge.raw", "truncated");
}

TEST(VolumeSlabs, CompressedAndOtherFormatsAreRefused) {
  const std::string dir = tmpDir();
  std::ostringstream mha;
  mha << "NDims = 3\nDimSize = " << NX << " " << NY << " " << NZ
      << "\nElementType = MET_SHORT\nCompressedData = True\nElementDataFile = LOCAL\n"
      << "not really zlib";
  writeBytes(join(dir, "z.mha"), mha.str());
  writeBytes(join(dir, "z.nii.gz"), "not really gzip");
  writeBytes(join(dir, "v.nrrd"), "NRRD0004\n");
  writeBytes(join(dir, "v.vti"), "<VTKFile/>");
  writeBytes(join(dir, "v.xyz"), "?");
  fs::create_directories(join(dir, "dicom"));
  for (const std::string name : {"z.mha", "z.nii.gz", "v.nrrd", "v.vti", "v.xyz", "dicom"})
    expectBadInput([&] { (void)VolumeSlabReader(join(dir, name)); }, join(dir, name),
                   "cannot be read by slabs; supported: ");
  expectBadInput([&] { (void)VolumeSlabReader(join(dir, "none.raw")); }, "none.raw",
                 "file not found");
}

TEST(VolumeSlabs, NonFiniteValuesAreRefusedInTheirSlab) {
  const std::string dir = tmpDir();
  std::string bytes = volumeBytes<float>(false, 0.5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(bytes.data() + size_t(4 * NX * NY + 3) * sizeof(float), &nan, sizeof nan);
  const VolumeSlabReader reader(writeRaw(dir, "nan.raw", "float32", bytes));
  EXPECT_EQ(reader.readSlices(0, 4).size(), size_t(4 * NX * NY));
  EXPECT_EQ(reader.readSlices(5, NZ).size(), size_t(4 * NX * NY));
  expectBadInput([&] { (void)reader.readSlices(2, 6); }, "nan.raw", "NaN or Inf");
}

TEST(VolumeSlabs, SliceRangesOutsideTheVolumeAreUsageErrors) {
  const std::string dir = tmpDir();
  const VolumeSlabReader reader(writeRaw(dir, "vol.raw", "int16", volumeBytes<int16_t>(false)));
  for (auto [zBegin, zEnd] : {std::pair{-1, 2}, std::pair{0, NZ + 1}, std::pair{3, 3},
                              std::pair{5, 2}, std::pair{NZ, NZ + 1}})
    expectError([&] { (void)reader.readSlices(zBegin, zEnd); }, ErrorKind::Usage, "vol.raw",
                "slices [");
  EXPECT_EQ(reader.readSlices(0, NZ).size(), size_t(N));
}
