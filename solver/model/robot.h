#pragma once
// What is known about a robot before calibration: the in-memory form of
// robot.toml (docs/FORMATS.md). A plain value type; parsing lives in src/formats.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace cdpr {

// The statics of Eq. (9)-(11) partition 6 equations over one reference cable
// and 2*(n-1) unknowns, which is square only for four cables.
inline constexpr int kCableCount = 4;

struct Winch {
  Eigen::Vector3d anchor_world = Eigen::Vector3d::Zero();        // [m] nominal pulley exit point
  Eigen::Vector3d attachment_platform = Eigen::Vector3d::Zero();  // [m] cable attachment point
};

// 1-sigma sensor noise used to whiten the residuals.
struct NoiseSigmas {
  double encoder_m = 0.010;
  double force_n = 5.0;
  double position_m = 0.005;
  double orientation_rad = 0.01;
};

struct Robot {
  std::string name;
  double gravity_mps2 = 9.81;
  double platform_mass_kg = 0.0;
  Eigen::Vector3d center_of_mass_platform = Eigen::Vector3d::Zero();  // [m] nominal
  double cable_linear_density_kgpm = 0.0;                             // [kg/m]
  int reference_cable = 0;
  std::optional<double> axial_stiffness_n;  // EA [N]; absent = unknown/inextensible
  std::vector<Winch> winches;               // cable order
  NoiseSigmas noise;

  int cable_count() const { return static_cast<int>(winches.size()); }
};

}  // namespace cdpr
