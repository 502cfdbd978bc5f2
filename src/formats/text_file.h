#pragma once
// Whole-file reads for the data formats (docs/FORMATS.md). Data files are small
// (kilobytes), so each parser works on the complete text in memory.

#include <string>
#include <string_view>

#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

// Reads a whole file; the error names the path and errno's reason.
Expected<std::string, FormatError> read_text_file(const std::string& path);

// Reads `path` and returns parse(text, path): the read_* functions of every
// format, with file errors passed through unchanged.
template <class Parse>
auto parse_file(const std::string& path, Parse parse) -> decltype(parse(std::string_view{}, path)) {
  const auto text = read_text_file(path);
  if (!text) return Unexpected{text.error()};
  return parse(*text, path);
}

}  // namespace cdpr::formats
