#pragma once
// `cdpr-calib solve`: robot.toml + samples.csv -> calibration.toml.

#include <string>

#include <CLI/CLI.hpp>

#include "solver/calibration/calibrate.h"

namespace cdpr::tools {

struct SolveArgs {
  std::string robot_path;
  std::string samples_path;
  std::string output_path = "calibration.toml";
  std::string truth_path;  // optional: compare with a simulator's truth.toml
  std::string report_dir;  // optional: write report.html there
  std::string model = "catenary";
  double huber_width = 0.0;
  double height_sigma_m = 1e-2;
  int max_iterations = CalibrationOptions{}.max_iterations;
  bool quiet = false;
  bool verbose = false;  // -v: also the stages calibrate() ran
  bool accept_misfit = false;
  bool least_squares = false;  // --no-robust
  double max_rejected_fraction = CalibrationOptions{}.max_rejected_fraction;
};

void add_solve_command(CLI::App& app, SolveArgs& args);
// Returns the process exit code: 0 done, 1 bad input, 2 the fit failed
// (or was refused for too many gross errors that no model term explains: a
// sensor fault), 3 the model does not fit (or the problem is
// under-determined) and --accept-misfit was not given; the calibration.toml
// is written in that case, with its model_warning; 4 refused for its gross
// errors, but a model term or a noise scale explains them: the model does
// not fit (nothing written).
inline constexpr int kExitRefusedModelMisfit = 4;
int run_solve(const SolveArgs& args);

}  // namespace cdpr::tools
