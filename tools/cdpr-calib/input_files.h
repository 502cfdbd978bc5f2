#pragma once
// The two inputs every cdpr-calib command reads: robot.toml and samples.csv.

#include <optional>
#include <string>
#include <vector>

#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr::tools {

struct CalibrationInputs {
  Robot robot;
  std::vector<Sample> samples;
};

// Empty after printing the format error (file, line, key) on stderr.
std::optional<CalibrationInputs> read_inputs(const std::string& robot_path, const std::string& samples_path);

}  // namespace cdpr::tools
