#include "src/daemon/run_marker.h"

#include <unistd.h>

#include <cerrno>

#include "src/formats/number_text.h"
#include "src/formats/toml_reader.h"
#include "src/formats/toml_writer.h"
#include "src/store/atomic_file.h"

namespace cdpr::daemon {

std::string format_run_marker(const RunMarker& marker) {
  std::string out;
  formats::append_line(out, "started = " + formats::toml_string(marker.started), "wall-clock start of the run (UTC)");
  formats::append_line(out, "updated = " + formats::toml_string(marker.updated), "last time this marker was written");
  formats::append_line(out, "waypoint = " + std::to_string(marker.waypoint), "1-based; 0 before planning");
  formats::append_line(out, "waypoints = " + std::to_string(marker.waypoints), "planned; 0 before planning");
  formats::append_line(out, "state = " + formats::toml_string(marker.state));
  formats::append_line(out, "elapsed_s = " + formats::shortest_text(marker.elapsed_s),
                       "daemon's monotonic clock since the run started");
  return out;
}

Expected<RunMarker, FormatError> parse_run_marker(std::string_view text, const std::string& source) {
  return formats::parse_toml<RunMarker>(text, source, [](formats::TomlReader& reader, const toml::table& root) {
    using formats::Presence;
    reader.check_keys(root, "", {{"started", Presence::kRequired}, {"updated", Presence::kRequired},
                                 {"waypoint", Presence::kRequired}, {"waypoints", Presence::kRequired},
                                 {"state", Presence::kRequired}, {"elapsed_s", Presence::kOptional}});
    RunMarker marker;
    marker.started = reader.string(root, "started", "");
    marker.updated = reader.string(root, "updated", "");
    marker.waypoint = reader.count(root, "waypoint", "");
    marker.waypoints = reader.count(root, "waypoints", "");
    marker.state = reader.string(root, "state", "");
    marker.elapsed_s = reader.optional_number(root, "elapsed_s", "", formats::Bound::kNonNegative).value_or(0.0);
    return marker;
  });
}

std::string describe_interrupted_run(const RunMarker& marker) {
  std::string text = "run interrupted at " + marker.updated;
  if (marker.waypoints > 0) {
    text += ", waypoint " + std::to_string(marker.waypoint) + " of " + std::to_string(marker.waypoints);
  }
  return text + " (" + marker.state + "; started " + marker.started + "; the daemon stopped or died during it)";
}

store::StoreResult<store::Done> RunMarkerFile::write(const RunMarker& marker) const {
  return store::write_file_atomically(state_dir_, kName, format_run_marker(marker), {}, 1);
}

store::StoreResult<store::Done> RunMarkerFile::remove() const {
  if (::unlink(path().c_str()) != 0) {
    if (errno == ENOENT) return store::Done{};
    return Unexpected{store::errno_error("unlink", path())};
  }
  return store::fsync_directory(state_dir_);
}

Expected<std::optional<RunMarker>, std::string> RunMarkerFile::read() const {
  const auto text = store::read_file(path());
  if (!text) {
    if (text.error().errno_value == ENOENT) return std::optional<RunMarker>{};
    return Unexpected{text.error().message()};
  }
  auto marker = parse_run_marker(*text, path());
  if (!marker) return Unexpected{marker.error().message()};
  return std::optional<RunMarker>{std::move(*marker)};
}

}  // namespace cdpr::daemon
