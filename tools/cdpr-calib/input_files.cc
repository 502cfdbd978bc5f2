#include "input_files.h"

#include <cstdio>

#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::tools {

std::optional<CalibrationInputs> read_inputs(const std::string& robot_path, const std::string& samples_path) {
  auto robot = formats::read_robot_toml(robot_path);
  if (!robot) {
    std::fprintf(stderr, "cdpr-calib: %s\n", robot.error().message().c_str());
    return std::nullopt;
  }
  auto samples = formats::read_samples_csv(samples_path, robot->cable_count());
  if (!samples) {
    std::fprintf(stderr, "cdpr-calib: %s\n", samples.error().message().c_str());
    return std::nullopt;
  }
  return CalibrationInputs{std::move(*robot), std::move(*samples)};
}

}  // namespace cdpr::tools
