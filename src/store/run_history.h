#pragma once
// Every calibration run's data, kept in the store's history beside the
// calibrations (docs/FORMATS.md "History entry of a run"):
//
//   history/run-000007/robot.toml        the robot description the run used
//   history/run-000007/samples.csv       the samples it measured (docs/FORMATS.md)
//   history/run-000007/run.toml          its log: waypoints, skips and why, faults, robot time, outcome
//   history/run-000007/calibration.toml  the fit it validated (absent when none)
//   history/run-000007/report.html       that fit's report (absent when none)
//
// Runs are numbered on their own (a failed run has no calibration sequence
// number); run.toml's `calibration` names the history version a run
// committed. Each file is written atomically (atomic_file.h), so a crash
// leaves every file old or new, complete; a run the daemon did not finish
// keeps outcome "running" until recover_interrupted() at the next start.
//
// Disk budget: prune() removes whole entries, oldest first, until the
// entries fit the budget, but never an entry whose calibration.toml is one
// of the protected texts (the current calibration, a fit waiting in
// pending/), nor one still running, nor the newest (the last run, which
// the daemon's status names). An entry without a readable run.toml (a
// crash between its mkdir and its first file) is pruned like any other.
//
// Not thread-safe; the daemon uses one object on one thread at a time (its
// writer thread), and reads entries from the loop thread only through
// files written atomically. No exceptions: failures are StoreErrors naming
// the path and errno.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "src/formats/run_log_toml.h"
#include "src/store/store_error.h"

namespace cdpr::store {

// How far the newest run had come when its daemon stopped (the run marker,
// written at every waypoint): run.toml is only rewritten at a sample.
struct RunProgress {
  int waypoints_planned = 0;
  double robot_time_s = 0.0;  // [s] daemon's monotonic clock since the run started
};

struct RunEntry {
  int run = 0;
  std::string path;         // the entry's directory
  bool valid = false;       // run.toml parses
  formats::RunLog log;      // when valid
  std::string problem;      // why not valid
  std::uintmax_t bytes = 0; // of its files
};

class RunHistory {
 public:
  static constexpr const char* kLogName = "run.toml";
  static constexpr const char* kSamplesName = "samples.csv";
  static constexpr const char* kRobotName = "robot.toml";
  static constexpr const char* kCalibrationName = "calibration.toml";
  static constexpr const char* kReportName = "report.html";

  // `history_dir`: the store's history directory (CalibrationStore::history_dir()).
  explicit RunHistory(std::string history_dir) : dir_(std::move(history_dir)) {}

  static std::string entry_name(int run);  // "run-000007"
  std::string entry_path(int run) const;
  const std::string& dir() const { return dir_; }

  // All entries, newest first (run.toml parsed, sizes summed).
  [[nodiscard]] StoreResult<std::vector<RunEntry>> entries() const;
  // One more than the highest run number present (1 when none).
  [[nodiscard]] StoreResult<int> next_run() const;

  // Creates the entry's directory (durably) when missing.
  [[nodiscard]] StoreResult<Done> create(int run) const;
  // Replaces file `name` of entry `run` atomically.
  [[nodiscard]] StoreResult<Done> write(int run, const std::string& name, std::string_view content) const;

  // Entries still "running" (their daemon stopped or died mid-run) become
  // "interrupted" with `why` as the reason; temp files a crash left in any
  // entry are removed. `newest`: the newest such entry's waypoints planned
  // and robot time, where they exceed what its run.toml says. Returns the
  // entries changed.
  [[nodiscard]] StoreResult<std::vector<int>> recover_interrupted(
      const std::string& finished, const std::string& why,
      const std::optional<RunProgress>& newest = std::nullopt) const;

  // Removes the oldest unprotected entries until all fit `budget_bytes`
  // (see above); returns the runs removed, oldest first.
  [[nodiscard]] StoreResult<std::vector<int>> prune(std::uintmax_t budget_bytes,
                                                    const std::vector<std::string>& protected_calibrations) const;

  // Entry `run` (its run.toml parsed; not valid when unreadable), or the
  // newest for run 0; none when there is no such entry.
  std::optional<RunEntry> find(int run) const;
  // Whether entry `run` is there (a run pruned meanwhile is not).
  bool exists(int run) const;

  // The newest entry whose calibration.toml is exactly `calibration_text`.
  std::optional<RunEntry> find_by_calibration(const std::string& calibration_text) const;

 private:
  StoreResult<std::vector<int>> runs() const;  // ascending
  RunEntry read_entry(int run) const;
  StoreResult<Done> remove_entry(int run) const;

  std::string dir_;
};

}  // namespace cdpr::store
