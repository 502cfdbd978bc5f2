#include "solver/model/static_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "solver/model/cable_prediction.h"
#include "solver/model/initial_guess.h"
#include "solver/model/sample.h"
#include "solver/nls/dense_damped_solver.h"

namespace cdpr {
namespace {

constexpr int kMaxIterations = 200;  // trial steps
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

  // Levenberg-Marquardt on the four height residuals (a square system: its
  // least-squares minimum is the root), Jacobian by central differences
  // (angles step 1e-6 rad, forces relative 1e-6). The initial radius makes
  // the first steps nearly Newton's; the damping rises where the statics
  // turn sharply or a trial leaves the model (a cable would push).
  DenseDampedOptions options;
  options.max_trials = kMaxIterations;
  options.residual_tolerance = kHeightToleranceM;
  DenseDampedSolver<4, 4> solver(options);
  const DenseDampedSummary summary = solver.minimize_numeric(u, [&](const Unknowns& at, Eigen::Vector4d& r) {
    const std::optional<Eigen::Vector4d> heights = residuals(robot, anchors, position_world, at);
    if (heights) r = *heights;
    return heights.has_value();
  });
  if (summary.stop == DenseDampedStop::kNotEvaluable) {
    return fail("no equilibrium near the level pose (a cable would push or statics singular)");
  }
  if (summary.stop == DenseDampedStop::kJacobianNotEvaluable) return fail("statics fail next to the iterate");

  StaticPose result;
  std::array<CablePrediction, kCableCount> cables;
  const std::optional<Eigen::Vector4d> r = residuals(robot, anchors, position_world, u, &cables);
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
