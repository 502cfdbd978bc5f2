#pragma once
// Text pieces for writing the TOML formats of docs/FORMATS.md by hand, so the
// files keep the documented layout and comments (a TOML library's
// serializer would reorder keys and drop comments).
//
// Numbers are written in the shortest form that reads back to the same
// double, so format -> parse round-trips exactly.

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace cdpr::formats {

// Shortest round-trip text; integral values get ".0" so they read as floats
// to a human ("34.0"); non-finite values as TOML's nan/inf (which our parsers refuse).
std::string toml_number(double value);
std::string toml_vector3(const Eigen::Vector3d& value);       // "[x, y, z]"
std::string toml_numbers(const std::vector<double>& values);  // "[a, b, ...]"
std::string toml_string(std::string_view value);              // quoted, escaped basic string
std::string toml_strings(const std::vector<std::string>& values);
std::string toml_key(std::string_view key);  // bare if possible, quoted otherwise

// Appends "assignment   # comment\n", comments aligned in one column as in docs/FORMATS.md.
void append_line(std::string& out, std::string_view assignment, std::string_view comment = {});

// True when `text` is a TOML offset date-time (RFC 3339 with a zone), e.g.
// "2026-11-22T10:15:00Z", so it can be written unquoted.
bool is_offset_date_time(std::string_view text);

}  // namespace cdpr::formats
