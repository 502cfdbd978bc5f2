#pragma once
// robot.toml (docs/FORMATS.md): parse and format. Unknown keys, missing required
// keys, wrong types and out-of-range values are refused with file, line, key.

#include <string>
#include <string_view>

#include "solver/model/robot.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

// `source` names the input in error messages (usually its path). Keys are
// named by dotted path with 0-based table indices ("winch[2].anchor").
// Beyond docs/FORMATS.md: exactly kCableCount [[winch]] tables (the statics are
// square only for four cables), masses, densities, gravity, EA and sigmas
// > 0, cable.reference one of the cable indices. Integers are accepted as
// numbers. Never throws.
Expected<Robot, FormatError> parse_robot_toml(std::string_view text, const std::string& source);
Expected<Robot, FormatError> read_robot_toml(const std::string& path);
// The docs/FORMATS.md layout with comments; parse_robot_toml reads it back to an
// identical Robot (shortest round-trip number text).
std::string format_robot_toml(const Robot& robot);

}  // namespace cdpr::formats
