#pragma once
// samples.csv (FORMATS.md): one row per static pose. Columns are matched by
// header name; a missing, non-finite or extra value is refused with the row
// (file line) and column; rows are never silently dropped.

#include <string>
#include <string_view>
#include <vector>

#include "solver/sample.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

// `cable_count` is the number of [[winch]] tables; enc0..enc<n-1> must all be present.
Expected<std::vector<Sample>, FormatError> parse_samples_csv(std::string_view text, const std::string& source,
                                                             int cable_count);
Expected<std::vector<Sample>, FormatError> read_samples_csv(const std::string& path, int cable_count);
std::string format_samples_csv(const std::vector<Sample>& samples);

}  // namespace cdpr::formats
