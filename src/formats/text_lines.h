#pragma once
// Line and field splitting for the line-oriented formats (samples.csv).
// Views point into the caller's text, which must outlive them.

#include <string_view>
#include <vector>

namespace cdpr::formats {

struct TextLine {
  int number = 0;         // 1-based line number in the file, for error messages
  std::string_view text;  // without the line ending ("\n" or "\r\n") and surrounding blanks
};

// Spaces and tabs removed from both ends.
std::string_view trim(std::string_view text);

// The lines that carry content: blank lines and lines whose first non-blank
// character is '#' are skipped, but keep counting towards line numbers.
std::vector<TextLine> content_lines(std::string_view text);

// Splits on `separator`, trimming each field; "a,,b" gives three fields and
// "a," two, so a missing value is seen as an empty field, never skipped.
std::vector<std::string_view> split_fields(std::string_view line, char separator);

}  // namespace cdpr::formats
