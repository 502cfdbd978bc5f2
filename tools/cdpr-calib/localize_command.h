#pragma once
// `cdpr-calib localize robot.toml calibration.toml samples.csv`: the pose
// from the cables of every row (solver/operation/localize.h), its sigma and,
// the row's measured pose being there, the difference in sigmas
// (docs/operation.md).

#include <string>

#include <CLI/CLI.hpp>

#include "operation_inputs.h"

namespace cdpr::tools {

struct LocalizeArgs {
  OperationPaths inputs;
  std::string output_path;       // CSV; empty = stdout
  std::string true_poses_path;   // optional: a samples.csv whose poses are the truth (cdpr-sim --rests)
  bool exact_calibration = false;  // the calibration held exact instead of as priors
  std::string calibration_samples_path;  // the samples the calibration was fitted on: its joint covariance
  double height_sigma_m = 1e-2;
};

void add_localize_command(CLI::App& app, LocalizeArgs& args);
// Exit code: 0 every row localized, 1 bad input or output, 2 some row had no pose.
int run_localize(const LocalizeArgs& args);

}  // namespace cdpr::tools
