#pragma once
// A lexical check run before toml++ sees a document, for a bug of the toml++
// 3.3.0 that Debian 12 ships: a non-ASCII character where toml++ looks for
// whitespace (outside strings and comments, or first on the line after a
// line-ending backslash in a """ string) can reach __builtin_unreachable()
// in toml++'s is_non_ascii_horizontal_whitespace(): undefined behaviour in
// the daemon (upstream marzer/tomlplusplus#295 and #190; found by
// fuzz_calibration_toml). Outside strings and comments TOML 1.0 allows only
// ASCII anyway, so no valid file is refused but for the rare second case.
// toml++ reads a bare value (number, boolean, date-time) up to the next
// whitespace, ',', ']', '}' or '#' through that test, quotes included, so a
// quote inside such a value opens no string here either (found by
// fuzz_robot_toml: `[0.0"""` followed by U+025F). After a backslash in a
// string toml++ tests the next character, and any blanks and newlines after
// it, for whitespace too (found by both TOML fuzzers: U+FEF7, U+FE7F).

#include <optional>
#include <string>
#include <string_view>

#include "src/formats/format_error.h"

namespace cdpr::formats {

// The first non-ASCII byte at a place listed above, as an error naming its
// line; nullopt when there is none. Tracks comments, basic, literal and
// multi-line strings, and where values start (after '=', in arrays); never
// reads past `text`.
std::optional<FormatError> find_unsafe_non_ascii(std::string_view text, const std::string& source);

}  // namespace cdpr::formats
