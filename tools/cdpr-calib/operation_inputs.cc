#include "operation_inputs.h"

#include <cstdio>

#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::tools {

void add_operation_inputs(CLI::App& command, OperationPaths& paths) {
  command.add_option("robot", paths.robot, "robot.toml: geometry, masses and sensor noise")
      ->required()
      ->check(CLI::ExistingFile);
  command.add_option("calibration", paths.calibration, "calibration.toml: the committed calibration")
      ->required()
      ->check(CLI::ExistingFile);
  command.add_option("samples", paths.samples, "samples.csv: the rests, in the order the robot made them")
      ->required()
      ->check(CLI::ExistingFile);
}

std::optional<OperationInputs> read_operation_inputs(const OperationPaths& paths) {
  auto robot = formats::read_robot_toml(paths.robot);
  if (!robot) {
    std::fprintf(stderr, "cdpr-calib: %s\n", robot.error().message().c_str());
    return std::nullopt;
  }
  auto calibration = formats::read_calibration_toml(paths.calibration);
  if (!calibration) {
    std::fprintf(stderr, "cdpr-calib: %s\n", calibration.error().message().c_str());
    return std::nullopt;
  }
  auto rests = formats::read_samples_csv(paths.samples, robot->cable_count());
  if (!rests) {
    std::fprintf(stderr, "cdpr-calib: %s\n", rests.error().message().c_str());
    return std::nullopt;
  }
  return OperationInputs{std::move(*robot), std::move(*calibration), std::move(*rests)};
}

bool read_calibration_covariance(const std::string& samples_path, const OperationInputs& in, double height_sigma_m,
                                 std::optional<CalibrationCovariance>& out) {
  auto samples = formats::read_samples_csv(samples_path, in.robot.cable_count());
  if (!samples) {
    std::fprintf(stderr, "cdpr-calib: %s\n", samples.error().message().c_str());
    return false;
  }
  std::string why;
  out = calibration_covariance(in.robot, in.calibration, *samples, height_sigma_m, &why);
  if (!out) std::fprintf(stderr, "cdpr-calib: %s: %s\n", samples_path.c_str(), why.c_str());
  return out.has_value();
}

}  // namespace cdpr::tools
