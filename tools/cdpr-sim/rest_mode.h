#pragma once
// `cdpr-sim --rests N`: a robot in operation instead of a calibration data
// set (sim/rest_sequence.h): N rests at random workspace points with one
// injected fault, for `cdpr-calib watch` and tools/operation-acceptance.sh.

#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "sim/dataset.h"

namespace cdpr::tools {

struct RestModeArgs {
  int rests = 0;  // 0: a calibration data set, not a rest sequence
  std::string fault = "none";
  int fault_cable = 0;
  double fault_size = 0.0;
  int fault_from = 0;
  std::string fault_com;  // x,y,z [m]
  int creep_rests = 10;
};

void add_rest_mode_options(CLI::App& app, RestModeArgs& args);

// Writes robot.toml, samples.csv (the rests, measured), true_poses.csv (the
// same rows with the true poses in place of the measured ones),
// truth.toml (the robot before the fault) and truth_after.toml (at the last
// rest) into `dir`, and prints the
// fault's truth. Exit code as cdpr-sim's.
int run_rest_mode(const sim::DatasetConfig& config, const RestModeArgs& args, const std::filesystem::path& dir);

}  // namespace cdpr::tools
