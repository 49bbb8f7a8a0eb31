// The VTK XML image data header, checked before vtkXMLImageDataReader parses the file (issue 13):
// that reader accepts a piece extent outside the whole extent (and leaks the arrays it made for
// it), and divides by the block size a compressed array's header declares. Checked here: the file
// type, byte order, header type and compressor; WholeExtent (ordered, within int), Origin,
// Spacing (> 0) and Direction finite and within fp32; every Piece's extent inside WholeExtent and
// a single piece equal to it; every DataArray's type, component count, format and appended
// offset; and for compressed arrays the block header (block count, block sizes) of inline
// binary and raw appended data. Throws BadInput "PATH: problem".
#pragma once

#include <string>

namespace visopt::io {

void checkVtiHeader(const std::string& path);

}  // namespace visopt::io
