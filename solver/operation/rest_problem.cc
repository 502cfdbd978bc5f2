#include "solver/operation/rest_problem.h"

#include <cmath>

#include <Eigen/Dense>

#include "solver/calibration/effect_pose_factor.h"
#include "solver/calibration/pose_prior_factor.h"
#include "solver/calibration/static_pose_factor.h"
#include "solver/model/static_pose.h"

namespace cdpr {
namespace {

// Gauss-Newton over the platform position with straight cables of the
// encoders' lengths: |a_i - (p + R b_i)| = l_i. Damped, so a start far off
// (the workspace centre) still walks in; the sag it ignores only moves the
// point the statics then start from.
Eigen::Vector3d straight_cable_position(const Robot& robot, const Calibration& calibration, const Sample& rest,
                                        const Pose& start) {
  Eigen::Vector3d p = start.position_world;
  const Eigen::Matrix3d R = start.world_R_platform.normalized().toRotationMatrix();
  double damping = 1e-3;
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::Matrix<double, kCableCount, 3> J;
    Eigen::Matrix<double, kCableCount, 1> r;
    for (int i = 0; i < kCableCount; ++i) {
      const Eigen::Vector3d chord = calibration.winches[i].anchor_world - (p + R * robot.winches[i].attachment_platform);
      const double length = chord.norm();
      if (!(length > 0.0)) return p;
      r(i) = length - (rest.encoder_m[i] - calibration.winches[i].offset_m);
      J.row(i) = -chord.transpose() / length;
    }
    const Eigen::Matrix3d H = J.transpose() * J;
    const Eigen::Vector3d step =
        -(H + damping * Eigen::Matrix3d(H.diagonal().asDiagonal()) + 1e-12 * Eigen::Matrix3d::Identity())
             .ldlt()
             .solve(J.transpose() * r);
    if (!step.allFinite()) return p;
    p += step;
    if (step.norm() < 1e-9) break;
  }
  return p;
}

}  // namespace

std::unique_ptr<Factor> make_rest_factor(const Robot& robot, int pose_index, const Sample& rest,
                                         const std::vector<Effect>& effects, double height_sigma_m) {
  if (effects.empty()) return std::make_unique<StaticPoseFactor>(robot, pose_index, rest, height_sigma_m, Loss{});
  return std::make_unique<EffectPoseFactor>(robot, pose_index, rest, height_sigma_m, Loss{}, effects);
}

std::unique_ptr<Factor> make_measured_pose_factor(const Robot& robot, int pose_index, const Sample& rest) {
  const SampleSigmas sigma = reading_sigmas(robot, rest);
  return std::make_unique<PosePriorFactor>(pose_index, Pose{rest.position_world, rest.world_R_platform},
                                           sigma.position_m, sigma.orientation_rad, Loss{});
}

bool has_measured_pose(const Sample& rest) {
  return rest.position_world.allFinite() && rest.world_R_platform.coeffs().allFinite() &&
         std::abs(rest.world_R_platform.norm() - 1.0) < 1e-6;
}

std::optional<RestStart> rest_start(const Robot& robot, const Calibration& calibration, const Sample& rest,
                                    const Pose& start, std::string* why) {
  std::array<Eigen::Vector3d, kCableCount> anchors;
  for (int i = 0; i < kCableCount; ++i) anchors[i] = calibration.winches[i].anchor_world;
  const Eigen::Vector3d position = straight_cable_position(robot, calibration, rest, start);
  std::string statics_why;
  std::optional<StaticPose> statics = solve_static_pose(robot, anchors, position, &statics_why);
  if (!statics) {
    // Straight cables put the platform too low by the sag; the start itself
    // may hold an equilibrium where that point does not.
    statics = solve_static_pose(robot, anchors, start.position_world, &statics_why);
  }
  if (!statics) {
    if (why) *why = "no equilibrium near the start: " + statics_why;
    return std::nullopt;
  }
  // solve_static_pose holds the yaw at zero; the solve that follows frees it.
  RestStart out;
  out.world_T_platform = statics->world_T_platform;
  out.reference_force = statics->reference_force;
  return out;
}

}  // namespace cdpr
