#include "src/formats/waypoints_csv.h"

#include <array>
#include <cmath>

#include "src/formats/number_text.h"
#include "src/formats/text_file.h"
#include "src/formats/text_lines.h"

namespace cdpr::formats {
namespace {

constexpr std::array<std::string_view, 4> kColumns{"x", "y", "z", "separation_sigma"};
constexpr std::size_t kRequiredColumns = 3;

FormatError error(const std::string& source, int line, std::string field, std::string reason) {
  return FormatError{source, line, std::move(field), std::move(reason)};
}

}  // namespace

Expected<std::vector<PlannedWaypoint>, FormatError> parse_waypoints_csv(std::string_view text,
                                                                        const std::string& source) {
  const std::vector<TextLine> lines = content_lines(text);
  if (lines.empty()) return Unexpected{error(source, 0, "", "no header: expected x,y,z[,separation_sigma]")};
  const std::vector<std::string_view> header = split_fields(lines.front().text, ',');
  if (header.size() < kRequiredColumns || header.size() > kColumns.size()) {
    return Unexpected{error(source, lines.front().number, "",
                            "header has " + std::to_string(header.size()) +
                                " columns; expected x,y,z[,separation_sigma]")};
  }
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c] != kColumns[c]) {
      return Unexpected{error(source, lines.front().number, std::string(header[c]),
                              "column " + std::to_string(c + 1) + " must be '" + std::string(kColumns[c]) + "'")};
    }
  }
  std::vector<PlannedWaypoint> waypoints;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const std::vector<std::string_view> fields = split_fields(lines[k].text, ',');
    if (fields.size() != header.size()) {
      return Unexpected{error(source, lines[k].number, "",
                              std::to_string(fields.size()) + " values, the header has " +
                                  std::to_string(header.size()))};
    }
    std::array<double, kColumns.size()> values{};
    for (std::size_t c = 0; c < fields.size(); ++c) {
      const std::optional<double> value = parse_number(fields[c]);
      if (!value || !std::isfinite(*value)) {
        return Unexpected{error(source, lines[k].number, std::string(kColumns[c]),
                                "'" + std::string(fields[c]) + "' is not a finite number")};
      }
      values[c] = *value;
    }
    if (values[3] < 0.0) {
      return Unexpected{error(source, lines[k].number, "separation_sigma", "must not be negative")};
    }
    waypoints.push_back({Eigen::Vector3d(values[0], values[1], values[2]), values[3]});
  }
  if (waypoints.empty()) return Unexpected{error(source, 0, "", "no waypoint rows after the header")};
  return waypoints;
}

Expected<std::vector<PlannedWaypoint>, FormatError> read_waypoints_csv(const std::string& path) {
  return parse_file(path, parse_waypoints_csv);
}

std::string format_waypoints_csv(const std::vector<PlannedWaypoint>& waypoints, std::string_view comment) {
  std::string text = "# " + std::string(comment) + "\nx,y,z,separation_sigma\n";
  for (const PlannedWaypoint& w : waypoints) {
    text += shortest_text(w.position_world.x()) + "," + shortest_text(w.position_world.y()) + "," +
            shortest_text(w.position_world.z()) + "," + shortest_text(w.separation_sigma) + "\n";
  }
  return text;
}

}  // namespace cdpr::formats
