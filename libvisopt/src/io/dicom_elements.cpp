#include "io/dicom_elements.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "io/file_util.h"
#include "visopt/error.h"

namespace visopt::io {

namespace {

constexpr uint32_t kUndefinedLength = 0xFFFFFFFFu;
constexpr int kMaxSequenceDepth = 16;

constexpr uint32_t tagOf(uint16_t group, uint16_t element) {
  return (uint32_t(group) << 16) | element;
}

// The elements vtkDICOMImageReader's helper turns into numbers or strings without checking
// their length, and how many bytes each needs (0: any non-empty value).
struct ReadByVtk {
  uint32_t tag;
  uint32_t bytes;
};
constexpr std::array<ReadByVtk, 16> kReadByVtk{{
    {tagOf(0x0002, 0x0010), 0},  // transfer syntax
    {tagOf(0x0018, 0x0050), 0},  // slice thickness
    {tagOf(0x0020, 0x000E), 0},  // series UID
    {tagOf(0x0020, 0x0013), 0},  // instance number
    {tagOf(0x0020, 0x0032), 0},  // image position (patient)
    {tagOf(0x0020, 0x0037), 0},  // image orientation (patient)
    {tagOf(0x0020, 0x1041), 0},  // slice location
    {tagOf(0x0028, 0x0004), 0},  // photometric interpretation
    {tagOf(0x0028, 0x0010), 2},  // rows
    {tagOf(0x0028, 0x0011), 2},  // columns
    {tagOf(0x0028, 0x0030), 0},  // pixel spacing
    {tagOf(0x0028, 0x0100), 2},  // bits allocated
    {tagOf(0x0028, 0x0103), 2},  // pixel representation
    {tagOf(0x0028, 0x1052), 0},  // rescale intercept
    {tagOf(0x0028, 0x1053), 0},  // rescale slope
    {tagOf(0x7FE0, 0x0010), 0},  // pixel data
}};

std::string tagText(uint32_t tag) {
  char text[16];
  std::snprintf(text, sizeof text, "(%04X,%04X)", tag >> 16, tag & 0xFFFFu);
  return text;
}

class ElementWalk {
 public:
  ElementWalk(const std::string& folder, const std::string& file)
      : folder_(folder), file_(file), in_(file, std::ios::binary), size_(checkedFileSize(file)) {}

  void run() {
    char magic[4] = {};
    in_.seekg(128);
    in_.read(magic, 4);
    pos_ = in_.gcount() == 4 && std::memcmp(magic, "DICM", 4) == 0 ? 132 : 0;
    bool pixelData = false;
    while (pos_ < size_) {
      const Element e = next();
      if (e.tag == tagOf(0x7FE0, 0x0010)) {
        pixelData = true;
        if (e.length == kUndefinedLength)
          fail("compressed (encapsulated) pixel data is not supported");
        checkPixelLength(e.length);
        // VTK's parser reads on past the pixel data (an empty element there crashed it): so
        // does this walk.
      }
    }
    if (!pixelData) fail("no pixel data");
  }

 private:
  struct Element {
    uint32_t tag = 0;
    uint32_t length = 0;
  };

  // vtkDICOMImageReader copies the whole pixel data element into an image of rows x columns x
  // samples values of bits-allocated bits: a longer element overran it (a heap overflow in the
  // DICOM fuzz target), a shorter one left it partly unread.
  void checkPixelLength(uint32_t length) const {
    if (bitsAllocated_ != 8 && bitsAllocated_ != 16 && bitsAllocated_ != 32)
      fail("bits allocated " + std::to_string(bitsAllocated_) + " (8, 16 or 32 are read)");
    if (samples_ != 1)
      fail(std::to_string(samples_) + " samples per pixel (colour images are not volumes)");
    const uint64_t need = uint64_t(rows_) * columns_ * (bitsAllocated_ / 8u);
    if (need == 0) fail("an image of " + std::to_string(rows_) + " x " + std::to_string(columns_));
    if (length != need && length != need + 1)  // + 1: an odd length padded to even
      fail("pixel data of " + std::to_string(length) + " bytes for an image of " +
           std::to_string(rows_) + " x " + std::to_string(columns_) + " x " +
           std::to_string(bitsAllocated_) + " bits (" + std::to_string(need) + " bytes)");
  }

  [[noreturn]] void fail(const std::string& problem) const {
    throwBadInput(folder_, fileName(file_) + ": " + problem);
  }

  void read(void* out, size_t bytes) {
    if (pos_ + bytes > size_) fail("truncated inside a data element header");
    in_.seekg(std::streamoff(pos_));
    in_.read(static_cast<char*>(out), std::streamsize(bytes));
    if (size_t(in_.gcount()) != bytes) fail("read error");
    pos_ += bytes;
  }
  uint16_t u16() {
    uint8_t b[2];
    read(b, 2);
    return bigEndian_ ? uint16_t(b[0] << 8 | b[1]) : uint16_t(b[1] << 8 | b[0]);
  }
  uint32_t u32() {
    uint8_t b[4];
    read(b, 4);
    return bigEndian_ ? uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | b[3]
                      : uint32_t(b[3]) << 24 | uint32_t(b[2]) << 16 | uint32_t(b[1]) << 8 | b[0];
  }

  // Reads one element header, checks it and moves past its value (through a whole sequence).
  Element next() {
    Element e;
    uint16_t group = u16();
    // Explicit VR big endian (retired, still met): the data set's headers swap after the meta
    // group, which is always little endian.
    if (bigEndianData_ && !bigEndian_ && group != 0x0002) {
      bigEndian_ = true;
      group = uint16_t(group << 8 | group >> 8);
    }
    e.tag = tagOf(group, u16());
    // The file meta group is always explicit VR little endian; the data set follows its
    // transfer syntax.
    const bool meta = group == 0x0002;
    const bool explicitVr = meta || explicitVr_;
    char vr[2] = {0, 0};
    if (group == 0xFFFE) {  // item and delimiters: tag + 4-byte length in every syntax
      e.length = u32();
    } else if (explicitVr) {
      read(vr, 2);
      static const char* kLong[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                    "SV", "UC", "UN", "UR", "UT", "UV"};
      bool longForm = false;
      for (const char* l : kLong) longForm = longForm || std::memcmp(vr, l, 2) == 0;
      if (longForm) {
        pos_ += 2;  // reserved
        e.length = u32();
      } else {
        e.length = u16();
      }
    } else {
      e.length = u32();
    }
    for (const ReadByVtk& r : kReadByVtk)
      if (r.tag == e.tag) {
        if (e.length == 0) fail("element " + tagText(e.tag) + " is empty");
        if (r.bytes && e.length != r.bytes && e.length != kUndefinedLength)
          fail("element " + tagText(e.tag) + " holds " + std::to_string(e.length) + " bytes, not " +
               std::to_string(r.bytes));
      }
    if (e.length == kUndefinedLength) {
      if (e.tag == tagOf(0x7FE0, 0x0010)) return e;
      skipUndefined(e.tag);
    } else {
      if (e.length > size_ - pos_)
        fail("element " + tagText(e.tag) + " declares " + std::to_string(e.length) +
             " bytes where " + std::to_string(size_ - pos_) + " remain (truncated or corrupt)");
      if (e.tag == tagOf(0x0002, 0x0010)) readTransferSyntax(e.length);
      if (depth_ == 0) readImageNumber(e);
      const bool sequence = std::memcmp(vr, "SQ", 2) == 0 || e.tag == tagOf(0xFFFE, 0xE000);
      if (sequence)
        walkDefined(e.tag, pos_ + e.length);
      else
        pos_ += e.length;
    }
    return e;
  }

  // A sequence or item of undefined length: its elements up to the matching delimiter.
  void skipUndefined(uint32_t opener) {
    if (++depth_ > kMaxSequenceDepth) fail("sequences nested deeper than 16 levels");
    const uint32_t closer =
        opener == tagOf(0xFFFE, 0xE000) ? tagOf(0xFFFE, 0xE00D) : tagOf(0xFFFE, 0xE0DD);
    for (;;) {
      if (pos_ >= size_) fail("truncated: a sequence " + tagText(opener) + " does not end");
      const Element e = next();
      if (e.tag == closer) break;
    }
    --depth_;
  }

  // A sequence or item of defined length: its elements must end exactly where it does.
  void walkDefined(uint32_t opener, uint64_t end) {
    if (++depth_ > kMaxSequenceDepth) fail("sequences nested deeper than 16 levels");
    while (pos_ < end) next();
    if (pos_ != end) fail("the elements of " + tagText(opener) + " overrun its length");
    --depth_;
  }

  // Rows, columns, bits allocated and samples per pixel of the image itself (not of an icon
  // inside a sequence).
  void readImageNumber(const Element& e) {
    uint16_t* target = e.tag == tagOf(0x0028, 0x0010)   ? &rows_
                       : e.tag == tagOf(0x0028, 0x0011) ? &columns_
                       : e.tag == tagOf(0x0028, 0x0100) ? &bitsAllocated_
                       : e.tag == tagOf(0x0028, 0x0002) ? &samples_
                                                        : nullptr;
    if (!target || e.length != 2) return;
    const size_t at = pos_;
    *target = u16();
    pos_ = at;
  }

  void readTransferSyntax(uint32_t length) {
    std::string uid(std::min<uint32_t>(length, 64), '\0');
    const size_t at = pos_;
    read(uid.data(), uid.size());
    pos_ = at;
    while (!uid.empty() && (uid.back() == '\0' || uid.back() == ' ')) uid.pop_back();
    explicitVr_ = uid != "1.2.840.10008.1.2";
    bigEndianData_ = uid == "1.2.840.10008.1.2.2";
  }

  const std::string& folder_;
  const std::string& file_;
  std::ifstream in_;
  uint64_t size_ = 0, pos_ = 0;
  bool explicitVr_ = true, bigEndian_ = false, bigEndianData_ = false;
  int depth_ = 0;
  uint16_t rows_ = 0, columns_ = 0, bitsAllocated_ = 0, samples_ = 1;
};

}  // namespace

void checkDicomElements(const std::string& folder, const std::string& file) {
  ElementWalk(folder, file).run();
}

}  // namespace visopt::io
