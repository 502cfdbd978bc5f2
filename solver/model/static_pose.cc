#include "solver/model/static_pose.h"

#include <cmath>
#include <optional>
#include <utility>

#include <Eigen/LU>

#include "solver/model/cable_prediction.h"
#include "solver/model/initial_guess.h"
#include "solver/model/sample.h"

namespace cdpr {
namespace {

constexpr int kMaxIterations = 50;
constexpr double kHeightToleranceM = 1e-9;

using Unknowns = Eigen::Vector4d;  // roll [rad], pitch [rad], f_h [N], f_v [N]

Pose pose_of(const Eigen::Vector3d& position_world, const Unknowns& u) {
  Pose pose;
  pose.position_world = position_world;
  pose.world_R_platform = so3_exp(Eigen::Vector3d(u(0), u(1), 0.0));
  return pose;
}

// Height residuals of Eq. (15) for every cable; empty when the statics fail.
std::optional<Eigen::Vector4d> residuals(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                         const Eigen::Vector3d& position_world, const Unknowns& u,
                                         std::array<CablePrediction, kCableCount>* cables_out = nullptr) {
  const Pose pose = pose_of(position_world, u);
  const auto cables = predict_cables(robot, anchors, pose, u.tail<2>());
  if (!cables) return std::nullopt;
  Eigen::Vector4d r;
  for (int i = 0; i < kCableCount; ++i) {
    r(i) = (*cables)[i].end_height_m - pose.transform(robot.winches[i].attachment_platform).z();
  }
  if (cables_out) *cables_out = *cables;
  return r;
}

}  // namespace

std::array<Eigen::Vector3d, kCableCount> nominal_anchors(const Robot& robot) {
  std::array<Eigen::Vector3d, kCableCount> anchors;
  for (int i = 0; i < kCableCount; ++i) anchors[i] = robot.winches[i].anchor_world;
  return anchors;
}

std::optional<StaticPose> solve_static_pose(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Eigen::Vector3d& position_world, std::string* why) {
  const auto fail = [why](std::string message) -> std::optional<StaticPose> {
    if (why) *why = std::move(message);
    return std::nullopt;
  };
  if (robot.cable_count() != kCableCount) return fail("the statics need exactly 4 cables");
  Sample level;
  level.position_world = position_world;
  Unknowns u;
  u << 0.0, 0.0, paper_reference_force_guess(robot, anchors, level);

  auto r = residuals(robot, anchors, position_world, u);
  if (!r) return fail("no equilibrium near the level pose (a cable would push or statics singular)");
  for (int iteration = 0; iteration < kMaxIterations && r->cwiseAbs().maxCoeff() > kHeightToleranceM; ++iteration) {
    // Central differences: angles step 1e-6 rad, forces relative 1e-6.
    Eigen::Matrix4d jacobian;
    for (int j = 0; j < 4; ++j) {
      const double h = j < 2 ? 1e-6 : 1e-6 * std::max(1.0, std::abs(u(j)));
      Unknowns plus = u, minus = u;
      plus(j) += h;
      minus(j) -= h;
      const auto r_plus = residuals(robot, anchors, position_world, plus);
      const auto r_minus = residuals(robot, anchors, position_world, minus);
      if (!r_plus || !r_minus) return fail("statics fail next to the iterate");
      jacobian.col(j) = (*r_plus - *r_minus) / (2.0 * h);
    }
    const Eigen::FullPivLU<Eigen::Matrix4d> lu(jacobian);
    if (!lu.isInvertible()) return fail("singular statics Jacobian");
    const Unknowns step = -lu.solve(*r);
    // Backtracking: accept the first fraction that lowers the residual.
    bool accepted = false;
    for (double fraction = 1.0; fraction > 1e-4; fraction *= 0.5) {
      const Unknowns trial = u + fraction * step;
      const auto r_trial = residuals(robot, anchors, position_world, trial);
      if (r_trial && r_trial->norm() < r->norm()) {
        u = trial;
        r = r_trial;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
  }

  StaticPose result;
  std::array<CablePrediction, kCableCount> cables;
  r = residuals(robot, anchors, position_world, u, &cables);
  if (!r) return fail("statics fail at the solution");
  result.height_residual_m = r->cwiseAbs().maxCoeff();
  if (!(result.height_residual_m < 1e-6)) {
    return fail("no equilibrium found (height residual " + std::to_string(result.height_residual_m) + " m)");
  }
  result.world_T_platform = pose_of(position_world, u);
  result.reference_force = u.tail<2>();
  for (int i = 0; i < kCableCount; ++i) {
    result.arc_length_m[i] = cables[i].arc_length_m;
    result.tension_n[i] = cables[i].tension_n;
  }
  return result;
}

}  // namespace cdpr
