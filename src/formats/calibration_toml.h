#pragma once
// calibration.toml and truth.toml (FORMATS.md): parse and format.

#include <string>
#include <string_view>

#include "solver/calibration.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"
#include "src/formats/text_file.h"

namespace cdpr::formats {

Expected<Calibration, FormatError> parse_calibration_toml(std::string_view text, const std::string& source);
Expected<Calibration, FormatError> read_calibration_toml(const std::string& path);
std::string format_calibration_toml(const Calibration& calibration);

Expected<Truth, FormatError> parse_truth_toml(std::string_view text, const std::string& source);
Expected<Truth, FormatError> read_truth_toml(const std::string& path);
std::string format_truth_toml(const Truth& truth);

}  // namespace cdpr::formats
