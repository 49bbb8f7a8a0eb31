// A NIfTI-1 header written by hand (348 bytes and 4 extension bytes, either byte order), for the
// reader tests that need files with a chosen orientation, scaling, datatype or a broken field.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

namespace visopt::test_files {

struct NiftiSpec {
  int16_t dim[8] = {3, 1, 1, 1, 1, 1, 1, 1};
  float spacing[3] = {1.f, 1.f, 1.f};
  int16_t datatype = 4, bitpix = 16;  // int16
  float qfac = 1.f;
  float quatern[3] = {0, 0, 0};
  float qoffset[3] = {0, 0, 0};
  int16_t qformCode = 1, sformCode = 0;
  float srow[3][4] = {};
  float sclSlope = 1.f, sclInter = 0.f;
  bool bigEndian = false;
};

inline std::string niftiHeader(const NiftiSpec& s) {
  std::string h(352, '\0');
  auto put = [&](size_t offset, auto value) {
    char b[sizeof(value)];
    std::memcpy(b, &value, sizeof(value));
    if (s.bigEndian != (std::endian::native == std::endian::big))
      std::reverse(b, b + sizeof(value));
    std::memcpy(h.data() + offset, b, sizeof(value));
  };
  put(0, int32_t(348));
  for (int i = 0; i < 8; ++i) put(40 + 2 * size_t(i), s.dim[i]);
  put(70, s.datatype);
  put(72, s.bitpix);
  const float pixdim[8] = {s.qfac, s.spacing[0], s.spacing[1], s.spacing[2], 1, 1, 1, 1};
  for (int i = 0; i < 8; ++i) put(76 + 4 * size_t(i), pixdim[i]);
  put(108, 352.f);  // vox_offset
  put(112, s.sclSlope);
  put(116, s.sclInter);
  h[123] = char(2);  // xyzt_units: mm
  put(252, s.qformCode);
  put(254, s.sformCode);
  for (int i = 0; i < 3; ++i) put(256 + 4 * size_t(i), s.quatern[i]);
  for (int i = 0; i < 3; ++i) put(268 + 4 * size_t(i), s.qoffset[i]);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) put(280 + 16 * size_t(r) + 4 * size_t(c), s.srow[r][c]);
  std::memcpy(h.data() + 344, "n+1\0", 4);
  return h;
}

}  // namespace visopt::test_files
