#include "solver/model/cable_prediction.h"

#include "solver/model/catenary.h"
#include "solver/model/platform_statics.h"

namespace cdpr {

std::optional<std::array<CablePrediction, kCableCount>> predict_cables(
    const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors, const Pose& world_T_platform,
    const Eigen::Vector2d& reference_force) {
  StaticsInput in;
  in.world_T_platform = world_T_platform;
  in.reference_force = reference_force;
  in.anchor_world = anchors;
  std::array<CableStatics, kCableCount> cables;
  if (solve_platform_statics(robot, in, false, cables) != StaticsStatus::kOk) return std::nullopt;
  const double weight_per_length = robot.gravity_mps2 * robot.cable_linear_density_kgpm;
  std::array<CablePrediction, kCableCount> out;
  for (int i = 0; i < kCableCount; ++i) {
    const CableStatics& c = cables[i];
    if (!(c.f_h > 0.0)) return std::nullopt;
    const CatenaryOutput shape = evaluate_catenary({c.f_h, c.f_v, c.span, c.anchor_z, weight_per_length}, false);
    out[i] = {shape.arc_length, shape.end_height, c.f_h, c.f_v, std::hypot(c.f_h, c.f_v)};
  }
  return out;
}

}  // namespace cdpr
