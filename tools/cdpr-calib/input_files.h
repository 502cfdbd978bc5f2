#pragma once
// The two inputs every cdpr-calib command reads: robot.toml and samples.csv,
// given as two files or as one directory holding both under those names (a
// history entry of the daemon, docs/FORMATS.md "History entry of a run").

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr::tools {

struct CalibrationInputs {
  Robot robot;
  std::vector<Sample> samples;
};

// The positional arguments "robot" (a robot.toml or an entry directory)
// and "samples" (required unless "robot" is a directory) of `command`.
void add_input_options(CLI::App& command, std::string& robot_path, std::string& samples_path);

// Empty after printing the problem (file, line, key) on stderr. An empty
// `samples_path` with a directory `robot_path` reads the directory's
// robot.toml and samples.csv.
std::optional<CalibrationInputs> read_inputs(const std::string& robot_path, const std::string& samples_path);

}  // namespace cdpr::tools
