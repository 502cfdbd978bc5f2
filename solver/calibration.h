#pragma once
// What calibration produces (calibration.toml) and what a simulator knows
// (truth.toml), FORMATS.md. Plain value types.

#include <array>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/robot.h"

namespace cdpr {

struct WinchCalibration {
  Eigen::Vector3d anchor_world = Eigen::Vector3d::Zero();  // [m] estimated pulley exit point
  Eigen::Vector3d anchor_sigma = Eigen::Vector3d::Zero();  // [m] 1-sigma per axis
  double offset_m = 0.0;                                   // [m] encoder offset
  double offset_sigma_m = 0.0;                             // [m] 1-sigma
};

struct FitSummary {
  double cost_initial = 0.0;
  double cost_final = 0.0;
  int iterations = 0;
  double rms_encoder_m = 0.0;
  double rms_force_n = 0.0;
};

// Fitted parameters of extra model terms, by name (FORMATS.md [effects]);
// scalars hold one value, per-cable terms one value per cable.
using EffectValues = std::map<std::string, std::vector<double>>;

struct Calibration {
  int format = 1;
  std::string created;  // RFC 3339 UTC, e.g. 2026-11-22T10:15:00Z
  std::string robot;
  std::vector<std::string> model{"catenary"};
  int samples = 0;
  std::vector<WinchCalibration> winches;
  FitSummary fit;
  EffectValues effects;
};

struct WinchTruth {
  Eigen::Vector3d anchor_world = Eigen::Vector3d::Zero();
  double offset_m = 0.0;
};

struct Truth {
  std::vector<WinchTruth> winches;
  EffectValues effects;
};

}  // namespace cdpr
