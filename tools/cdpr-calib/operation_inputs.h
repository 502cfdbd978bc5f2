#pragma once
// The three inputs of the operation commands (`localize`, `watch`,
// docs/operation.md): robot.toml, the committed calibration.toml and a
// samples.csv of rests.

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "solver/operation/calibration_covariance.h"

namespace cdpr::tools {

struct OperationPaths {
  std::string robot, calibration, samples;
};

struct OperationInputs {
  Robot robot;
  Calibration calibration;
  std::vector<Sample> rests;
};

void add_operation_inputs(CLI::App& command, OperationPaths& paths);
// Empty after printing the problem (file, line, key) on stderr.
std::optional<OperationInputs> read_operation_inputs(const OperationPaths& paths);

// The joint covariance of the calibration's anchors and offsets from the
// samples.csv it was fitted on (--calibration-samples); false after
// printing why not.
bool read_calibration_covariance(const std::string& samples_path, const OperationInputs& in, double height_sigma_m,
                                 std::optional<CalibrationCovariance>& out);

}  // namespace cdpr::tools
