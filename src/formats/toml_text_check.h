#pragma once
// A lexical check run before toml++ sees a document, for a bug of the toml++
// 3.3.0 that Debian 12 ships: a non-ASCII character where toml++ looks for
// whitespace (outside strings and comments, or first on the line after a
// line-ending backslash in a """ string) can reach __builtin_unreachable()
// in toml++'s is_non_ascii_horizontal_whitespace(): undefined behaviour in
// the daemon (upstream marzer/tomlplusplus#295 and #190; found by
// fuzz_calibration_toml). Outside strings and comments TOML 1.0 allows only
// ASCII anyway, so no valid file is refused but for the rare second case.

#include <optional>
#include <string>
#include <string_view>

#include "src/formats/format_error.h"

namespace cdpr::formats {

// The first non-ASCII byte at a place listed above, as an error naming its
// line; nullopt when there is none. Tracks comments, basic, literal and
// multi-line strings; never reads past `text`.
std::optional<FormatError> find_unsafe_non_ascii(std::string_view text, const std::string& source);

}  // namespace cdpr::formats
