#pragma once
// Whole-file reads for the data formats (FORMATS.md). Data files are small
// (kilobytes), so each parser works on the complete text in memory.

#include <string>

#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

// Reads a whole file; the error names the path and errno's reason.
Expected<std::string, FormatError> read_text_file(const std::string& path);

}  // namespace cdpr::formats
