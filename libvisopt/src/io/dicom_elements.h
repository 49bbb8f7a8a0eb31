// A walk over a DICOM file's data elements before VTK's DICOM parser sees it (issue 13): that
// parser trusts every length it reads (a value longer than the file is allocated and read past
// the end) and hands the elements it cares about to callbacks that dereference their values
// without checking that there are any (a Columns element of length 0 crashed it). Checked here:
// every element's value lies within the file, sequences and items of undefined length close,
// the elements vtkDICOMImageReader reads have values (two bytes for the unsigned shorts), and the
// pixel data is present, not encapsulated (compressed) and exactly the image's size. Throws
// BadInput "FOLDER: FILE: problem".
#pragma once

#include <string>

namespace visopt::io {

void checkDicomElements(const std::string& folder, const std::string& file);

}  // namespace visopt::io
