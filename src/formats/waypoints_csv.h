#pragma once
// waypoints.csv (docs/FORMATS.md): positions of the platform origin to rest
// at, one per row, with a column saying why each was chosen. Written by
// `cdpr-calib diagnose` (the poses that tell mimicking model terms apart),
// read by `cdpr-sim --extra-positions` to measure them.

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

struct PlannedWaypoint {
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();  // [m] platform origin
  // How far apart, in noise sigmas, the candidate models' predicted readings
  // are here (0 when not known): why this waypoint was chosen.
  double separation_sigma = 0.0;
};

// Header `x,y,z,separation_sigma` (the last column optional), columns in
// that order. Blank lines, '#' lines and CRLF are fine. Refused, with the
// file line and column: a missing or unknown column, a row with too few or
// too many values, a value that is not a finite number, a negative
// separation, a file without rows.
Expected<std::vector<PlannedWaypoint>, FormatError> parse_waypoints_csv(std::string_view text,
                                                                        const std::string& source);
Expected<std::vector<PlannedWaypoint>, FormatError> read_waypoints_csv(const std::string& path);
// A comment line, the header and one row per waypoint; parse_waypoints_csv
// reads back the same values.
std::string format_waypoints_csv(const std::vector<PlannedWaypoint>& waypoints, std::string_view comment);

}  // namespace cdpr::formats
