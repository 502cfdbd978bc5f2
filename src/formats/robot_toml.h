#pragma once
// robot.toml (FORMATS.md): parse and format. Unknown keys, missing required
// keys, wrong types and out-of-range values are refused with file, line, key.

#include <string>
#include <string_view>

#include "solver/robot.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

// `source` names the input in error messages (usually its path).
Expected<Robot, FormatError> parse_robot_toml(std::string_view text, const std::string& source);
Expected<Robot, FormatError> read_robot_toml(const std::string& path);
std::string format_robot_toml(const Robot& robot);

}  // namespace cdpr::formats
