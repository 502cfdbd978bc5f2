#pragma once
// One static pose as measured (a row of samples.csv, docs/FORMATS.md).

#include <algorithm>
#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "solver/model/robot.h"

namespace cdpr {

// The 1-sigma noise of one row's readings, when the row knows it better than
// robot.toml's per-reading [noise]: a row that averages a rest window is far
// less noisy than a single reading (samples.csv's optional sigma columns).
// Every value > 0 when given.
struct SampleSigmas {
  std::array<double, kCableCount> encoder_m{};  // [m] per cable
  double force_n = 0.0;                         // [N]
  double position_m = 0.0;                      // [m] each axis of the pose translation
  double orientation_rad = 0.0;                 // [rad] each axis of the pose rotation
};

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
  // The row's own noise; all zero when it has none and robot.toml's
  // per-reading sigmas weight it. (A plain value, not std::optional: GCC
  // warns falsely about moving a disengaged optional of doubles.)
  SampleSigmas sigma;
  bool has_own_sigma() const { return sigma.force_n > 0.0; }
};

// The sigmas that weight `sample` in a fit: its own when it has them, else
// the robot's per-reading ones.
inline SampleSigmas reading_sigmas(const Robot& robot, const Sample& sample) {
  if (sample.has_own_sigma()) return sample.sigma;
  SampleSigmas s;
  s.encoder_m.fill(robot.noise.encoder_m);
  s.force_n = robot.noise.force_n;
  s.position_m = robot.noise.position_m;
  s.orientation_rad = robot.noise.orientation_rad;
  return s;
}

// The sigma [m] that holds `sample`'s attachment-height consistency (Eq. 15)
// for a fit whose setting is `height_sigma_m`. The setting is made for rows
// weighted by robot.toml's per-reading noise; a row with its own, smaller
// sigmas is held tighter in proportion to its pose noise, so the identity
// keeps the same weight against the row's readings whichever noise they
// carry (left loose, it lets the fit bend the cables' shapes within noise
// the row does not have, and the sigmas come out larger than the errors).
// Never looser than the setting.
inline double row_height_sigma(const Robot& robot, const Sample& sample, double height_sigma_m) {
  if (!sample.has_own_sigma() || !(robot.noise.position_m > 0.0)) return height_sigma_m;
  return height_sigma_m * std::min(1.0, sample.sigma.position_m / robot.noise.position_m);
}

}  // namespace cdpr
