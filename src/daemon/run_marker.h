#pragma once
// The run marker: "<state_dir>/run-in-progress.toml", present exactly while
// a calibration runs, so that a daemon that was killed (or lost power)
// mid-run is known to have been at the next start:
//
//   started = "2026-11-25T17:40:02Z"   # wall-clock start of the run (UTC)
//   updated = "2026-11-25T17:43:10Z"   # last time the marker was written
//   waypoint = 7                       # 1-based waypoint of the run, 0 before planning
//   waypoints = 35                     # waypoints planned, 0 before planning
//   state = "settle"                   # the state machine's state then
//   elapsed_s = 191.4                  # the daemon's monotonic time since the run started
//                                      # (optional: absent in an older daemon's marker)
//
// The daemon loop writes it atomically (atomic_file.h) when a run starts, at
// every new waypoint and when the motion ends (solve), and removes it when
// the run ends (done or failed). A daemon stopped by SIGTERM mid-run aborts
// the run and leaves the marker: the next start reports that run too.
//
// Not thread-safe (the daemon's loop thread).

#include <optional>
#include <string>
#include <string_view>

#include "src/formats/expected.h"
#include "src/formats/format_error.h"
#include "src/store/store_error.h"

namespace cdpr::daemon {

struct RunMarker {
  std::string started;  // RFC 3339 UTC
  std::string updated;
  int waypoint = 0;
  int waypoints = 0;
  std::string state;
  double elapsed_s = 0.0;  // [s] daemon's monotonic clock, from the run's start to `updated`
};

std::string format_run_marker(const RunMarker& marker);
Expected<RunMarker, FormatError> parse_run_marker(std::string_view text, const std::string& source);
// "run interrupted at 2026-11-25T17:43:10Z, waypoint 7 of 35 (settle; started 2026-11-25T17:40:02Z)".
std::string describe_interrupted_run(const RunMarker& marker);

class RunMarkerFile {
 public:
  static constexpr const char* kName = "run-in-progress.toml";

  explicit RunMarkerFile(std::string state_dir) : state_dir_(std::move(state_dir)) {}

  [[nodiscard]] store::StoreResult<store::Done> write(const RunMarker& marker) const;
  // Removes the marker (absent is fine) and makes the removal durable.
  [[nodiscard]] store::StoreResult<store::Done> remove() const;
  // The marker left by an earlier daemon; nullopt when there is none. An
  // unreadable or unparsable marker is an error (its message names the file).
  Expected<std::optional<RunMarker>, std::string> read() const;

  std::string path() const { return state_dir_ + "/" + kName; }

 private:
  std::string state_dir_;
};

}  // namespace cdpr::daemon
