#pragma once
// One static pose as measured (a row of samples.csv, docs/FORMATS.md).

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "solver/model/robot.h"

namespace cdpr {

struct Sample {
  int id = 0;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();                // [m] platform origin
  Eigen::Quaterniond world_R_platform = Eigen::Quaterniond::Identity();    // unit, platform -> world
  std::array<double, kCableCount> encoder_m{};                             // [m] relative readings
  double force_n = 0.0;  // [N] load-cell tension of the reference cable at its attachment
  // Readings a calibration left out as gross errors (solver/calibration/calibrate.h):
  // the model fits the rest of the row without them. Not in samples.csv.
  std::array<bool, kCableCount> encoder_left_out{};
  bool force_left_out = false;
};

}  // namespace cdpr
