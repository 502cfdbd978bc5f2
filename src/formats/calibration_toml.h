#pragma once
// calibration.toml and truth.toml (docs/FORMATS.md): parse and format.

#include <string>
#include <string_view>

#include "solver/model/calibration.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"
#include "src/formats/text_file.h"

namespace cdpr::formats {

// Only format = 1 is read (any other version is refused before its keys are
// looked at); `created` must be a TOML offset date-time and comes back as
// RFC 3339 text ("2026-11-22T10:15:00Z"). Unknown keys, missing keys, wrong
// types, negative sigmas or counts are refused with file, line and key.
// [effects] values are a number (-> 1 value) or a non-empty array of numbers.
// Never throws.
Expected<Calibration, FormatError> parse_calibration_toml(std::string_view text, const std::string& source);
Expected<Calibration, FormatError> read_calibration_toml(const std::string& path);
// Writes format 1 whatever calibration.format says. Precondition: `created`
// is an RFC 3339 date-time with zone (written bare, as TOML requires);
// anything else aborts, since it would make a file no reader accepts.
// Round-trips exactly through parse_calibration_toml.
std::string format_calibration_toml(const Calibration& calibration);

// [[winch]] anchor, offset and an optional [effects] table, as above.
Expected<Truth, FormatError> parse_truth_toml(std::string_view text, const std::string& source);
Expected<Truth, FormatError> read_truth_toml(const std::string& path);
std::string format_truth_toml(const Truth& truth);

}  // namespace cdpr::formats
