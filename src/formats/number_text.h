#pragma once
// Numbers as text in the data formats: written in the shortest form that
// reads back to the same double (so files round-trip exactly), read strictly
// (the whole field must be the number).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cdpr::formats {

// Shortest text that std::from_chars reads back as exactly `value` ("34", "0.0724", "1e+20").
std::string shortest_text(double value);

// The number spelled by all of `text` (an optional leading '+' is allowed);
// nan and inf are returned as such, callers decide whether they are valid.
std::optional<double> parse_number(std::string_view text);
std::optional<std::int64_t> parse_integer(std::string_view text);

}  // namespace cdpr::formats
