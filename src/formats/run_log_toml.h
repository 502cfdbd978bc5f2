#pragma once
// run.toml (docs/FORMATS.md "run.toml"): the log of one calibration run of
// the daemon, kept in its history entry beside the run's samples.csv and
// robot.toml: when it ran, how long the robot worked, what became of every
// planned waypoint (sampled, or skipped and why), the faults, and the
// outcome. Times: wall clock as RFC 3339 UTC text, robot time in seconds
// of the daemon's monotonic clock since the run started.

#include <string>
#include <string_view>
#include <vector>

#include "src/formats/expected.h"
#include "src/formats/format_error.h"

namespace cdpr::formats {

// "running" while the run goes on (and what a crash leaves), then one of
// "committed", "failed", "aborted" (an operator's or a stopping daemon's
// abort) or "interrupted" (found "running" at the next start).
inline constexpr const char* kRunRunning = "running";
inline constexpr const char* kRunCommitted = "committed";
inline constexpr const char* kRunFailed = "failed";
inline constexpr const char* kRunAborted = "aborted";
inline constexpr const char* kRunInterrupted = "interrupted";

struct RunWaypoint {
  int index = 0;            // 1-based, in the plan's order
  std::string outcome;      // "sampled" or "skipped"
  double at_s = 0.0;        // robot time when it was sampled or given up
  int sample = -1;          // row id in samples.csv when sampled, else -1
  std::string why;          // why it was skipped; for a sampled one, a remark or empty
};

struct RunFault {
  double at_s = 0.0;
  std::string text;
};

struct RunLog {
  int run = 0;                 // the entry's number (run-000007: 7)
  std::string outcome = kRunRunning;
  std::string reason;          // the daemon's final sentence (what was committed, or why not)
  std::string robot;           // robot.toml name
  std::string started;         // RFC 3339 UTC
  std::string finished;        // empty while running
  double robot_time_s = 0.0;   // from the start to the end (or to the last write while running)
  int waypoints_planned = 0;   // the fixed plan's size, or the sequential strategy's max_count
  std::string strategy;        // "spread", "informative", "sequential"; empty before planning (and in old files)
  std::string stop;            // why the waypoints ended; empty while they go on (and in old files)
  int samples = 0;
  int skipped = 0;
  int calibration = 0;         // store sequence number committed by this run; 0 none
  std::string diagnosis;       // the discrepancy check's verdict on this run's data; empty: not run
  // A refit's entry (an operator's `calibctl commit --with-term`): the run
  // whose samples it refitted, whose log it copies; 0 for a run of the robot.
  int refit_of = 0;
  // A run through given waypoints appended to an earlier run: that run,
  // whose samples its samples.csv begins with; 0 otherwise.
  int extends = 0;
  std::vector<RunWaypoint> waypoints;
  std::vector<RunFault> faults;
};

std::string format_run_log_toml(const RunLog& log);
Expected<RunLog, FormatError> parse_run_log_toml(std::string_view text, const std::string& source);
Expected<RunLog, FormatError> read_run_log_toml(const std::string& path);

}  // namespace cdpr::formats
