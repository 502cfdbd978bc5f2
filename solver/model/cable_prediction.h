#pragma once
// The fitting model run forwards: cable lengths and forces at one pose from
// the statics (Eq. 5-11) and the catenary (Eq. 1-4). Used for initial
// offsets, reports and the model check against the simulator (Table I).

#include <array>
#include <optional>

#include <Eigen/Core>

#include "solver/nls/pose.h"
#include "solver/model/robot.h"

namespace cdpr {

struct CablePrediction {
  double arc_length_m = 0.0;    // Eq. (4)
  double end_height_m = 0.0;    // Eq. (1) at the attachment; equals its height at a consistent pose
  double f_h_n = 0.0;
  double f_v_n = 0.0;
  double tension_n = 0.0;       // |(f_h, f_v)| at the attachment
};

std::optional<std::array<CablePrediction, kCableCount>> predict_cables(
    const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors, const Pose& world_T_platform,
    const Eigen::Vector2d& reference_force);

}  // namespace cdpr
