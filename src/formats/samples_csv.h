#pragma once
// samples.csv (docs/FORMATS.md): one row per static pose. Columns are matched by
// header name; a missing, non-finite or extra value is refused with the row
// (file line) and column; rows are never silently dropped.

#include <string>
#include <string_view>
#include <vector>

#include "solver/model/sample.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

// `cable_count` is the number of [[winch]] tables; enc0..enc<n-1> must all
// be present (and cable_count must be kCableCount). Blank lines, '#' lines,
// CRLF endings and blanks around fields are fine. The sigma columns
// (sigma_enc0.., sigma_force, sigma_pos, sigma_rot) are optional, all or
// none; a row with them all empty has no own sigma (Sample::sigma). Refused: a missing,
// unknown or duplicate column; some sigma columns without the others, a
// row with some sigmas empty, a sigma not > 0; a row with too few or too many values; an
// empty, non-numeric or non-finite value; a sample id that is no integer or
// repeats; a quaternion whose norm is off 1 by more than 1e-3 (closer ones
// are normalised); a file without data rows. Errors carry the file line.
Expected<std::vector<Sample>, FormatError> parse_samples_csv(std::string_view text, const std::string& source,
                                                             int cable_count);
Expected<std::vector<Sample>, FormatError> read_samples_csv(const std::string& path, int cable_count);
// A comment line, the header and one row per sample in shortest round-trip
// number text: parse_samples_csv reads back identical samples. The sigma
// columns only when a sample has its own sigmas (the rows without leave them
// empty): samples without are written exactly as before the columns existed.
std::string format_samples_csv(const std::vector<Sample>& samples);

}  // namespace cdpr::formats
