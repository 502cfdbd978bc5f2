#include "input_files.h"

#include <cstdio>
#include <filesystem>

#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::tools {

void add_input_options(CLI::App& command, std::string& robot_path, std::string& samples_path) {
  command
      .add_option("robot", robot_path,
                  "robot.toml: nominal geometry, masses and sensor noise; or a directory holding robot.toml and "
                  "samples.csv (a history entry of cdpr-calibd: <state_dir>/history/run-NNNNNN)")
      ->required()
      ->check(CLI::ExistingPath);
  command.add_option("samples", samples_path, "samples.csv: one row per static pose (not with a directory)")
      ->check(CLI::ExistingFile);
}

std::optional<CalibrationInputs> read_inputs(const std::string& robot_arg, const std::string& samples_arg) {
  std::string robot_path = robot_arg;
  std::string samples_path = samples_arg;
  std::error_code error;
  if (std::filesystem::is_directory(robot_arg, error)) {
    if (!samples_arg.empty()) {
      std::fprintf(stderr, "cdpr-calib: %s is a directory: give it alone, or a robot.toml and a samples.csv\n",
                   robot_arg.c_str());
      return std::nullopt;
    }
    robot_path = robot_arg + "/robot.toml";
    samples_path = robot_arg + "/samples.csv";
  } else if (samples_arg.empty()) {
    std::fprintf(stderr, "cdpr-calib: samples.csv missing after %s (or give a directory holding both)\n",
                 robot_arg.c_str());
    return std::nullopt;
  }
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
