#pragma once
// `cdpr-calib watch robot.toml calibration.toml samples.csv`: the health
// test (solver/operation/health_watch.h) over the rows in order, as the
// daemon's watch mode runs it at every rest: when and what fired, the
// finding re-estimated over all rests since the change, and the re-fit it
// offers (docs/operation.md).

#include <string>

#include <CLI/CLI.hpp>

#include "operation_inputs.h"

namespace cdpr::tools {

struct WatchArgs {
  OperationPaths inputs;
  std::string refit_path;   // write the offered re-fit's calibration.toml here (empty: do not)
  std::string truth_path;   // truth.toml of the robot after the change (cdpr-sim --rests: truth_after.toml)
  std::string calibration_samples_path;  // the samples the calibration was fitted on: its joint covariance
  bool offsets_only = false;
  bool verbose = false;
  bool no_measured_pose = false;
  double clean_rests_per_false_alarm = 1e3;
  std::string calibration_error = "ignored";  // ignored, predictive or tracked (HealthWatchOptions)
  int calibration_error_rests = 0;
  double anchor_misnaming_rate = 0.01;
};

void add_watch_command(CLI::App& app, WatchArgs& args);
// Exit code: 0 the calibration held, 3 it went stale, 1 bad input or output.
int run_watch(const WatchArgs& args);

}  // namespace cdpr::tools
