#pragma once
// `cdpr-calib diagnose`: robot.toml + samples.csv -> which known effect the
// data show (solver/diagnosis/diagnosis.h), a text and HTML report and the calibration
// of the final model.

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace cdpr::tools {

struct DiagnoseArgs {
  std::string robot_path;
  std::string samples_path;
  std::string report_dir = "diagnosis";
  std::string truth_path;  // optional: simulated data
  std::string candidates;  // comma-separated model terms; empty = all
  int folds = 3;
  double alpha = 0.01;
  int max_added = 4;
  double height_sigma_m = 1e-2;
  int discriminate = 8;  // waypoints that tell a mimic set apart; 0: none
  std::vector<double> workspace;  // xmin,ymin,zmin,xmax,ymax,zmax of those waypoints; empty: the measured box
};

void add_diagnose_command(CLI::App& app, DiagnoseArgs& args);
// Exit code: 0 done (whatever was found), 1 bad input or output, 2 the workflow could not run.
int run_diagnose(const DiagnoseArgs& args);

}  // namespace cdpr::tools
