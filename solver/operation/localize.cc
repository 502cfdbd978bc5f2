#include "solver/operation/localize.h"

#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "solver/nls/levenberg_marquardt.h"
#include "solver/nls/problem.h"
#include "solver/operation/calibration_variables.h"
#include "solver/operation/rest_problem.h"

namespace cdpr {
namespace {

std::optional<LocalizedPose> no_pose(std::string* why, const std::string& what) {
  if (why) *why = what;
  return std::nullopt;
}

// The solver's tangent (d_p world, d_theta platform: solver/nls/pose.h) to
// the world-frame rotation vector: Exp(d_theta_world) R = R Exp(d_theta), so
// d_theta_world = R d_theta.
Eigen::Matrix<double, 6, 6> world_frame_covariance(const Eigen::MatrixXd& tangent, const Eigen::Quaterniond& q) {
  Eigen::Matrix<double, 6, 6> T = Eigen::Matrix<double, 6, 6>::Identity();
  T.bottomRightCorner<3, 3>() = q.normalized().toRotationMatrix();
  return T * tangent * T.transpose();
}

}  // namespace

std::optional<LocalizedPose> localize_rest(const Robot& robot, const Calibration& calibration, const Sample& rest,
                                           const Pose& start, const LocalizeOptions& options, std::string* why) {
  std::string problem_why;
  const std::optional<std::vector<Effect>> effects = calibration_effects(calibration, &problem_why);
  if (!effects) return no_pose(why, problem_why);
  if (options.use_measured_pose && !has_measured_pose(rest)) return no_pose(why, "the row has no measured pose");
  const std::optional<RestStart> first = rest_start(robot, calibration, rest, start, &problem_why);
  if (!first) return no_pose(why, problem_why);

  Problem problem;
  problem.add_pose(PoseKey(0), first->world_T_platform);
  problem.add_vector(ReferenceForceKey(0), first->reference_force);
  const auto uncertainty =
      options.calibration_priors ? CalibrationUncertainty::kPriors : CalibrationUncertainty::kHeldConstant;
  if (!add_calibration_variables(problem, calibration, *effects, uncertainty, &problem_why,
                                 options.calibration_covariance ? &*options.calibration_covariance : nullptr)) {
    return no_pose(why, problem_why);
  }
  problem.add_factor(make_rest_factor(robot, 0, rest, *effects, options.height_sigma_m));
  if (options.use_measured_pose) problem.add_factor(make_measured_pose_factor(robot, 0, rest));

  SolverOptions solver_options;
  solver_options.max_iterations = options.max_iterations;
  LevenbergMarquardt lm(problem, solver_options);
  const SolverSummary summary = lm.solve();
  if (!summary.usable()) return no_pose(why, "the pose solve failed: " + summary.message);
  const double chi_square = 2.0 * summary.final_cost;
  if (!(chi_square <= options.max_chi_square)) {
    return no_pose(why, "no equilibrium fits the readings: chi-square " + std::to_string(chi_square) +
                         " of the whitened residuals at the best pose (limit " +
                         std::to_string(options.max_chi_square) + ")");
  }
  const Eigen::MatrixXd tangent = lm.covariance({PoseKey(0)});
  if (tangent.rows() != 6 || !tangent.allFinite()) {
    return no_pose(why, "the pose is not observable from these readings (singular information matrix)");
  }

  LocalizedPose out;
  out.world_T_platform = problem.pose(PoseKey(0));
  out.reference_force = problem.vector(ReferenceForceKey(0));
  out.covariance = world_frame_covariance(tangent, out.world_T_platform.world_R_platform);
  out.cost = summary.final_cost;
  out.iterations = summary.iterations;
  out.converged = summary.termination == TerminationType::kConverged;
  return out;
}

Pose nominal_start(const Calibration& calibration, const Sample& rest) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double payout = 0.0;
  const int n = static_cast<int>(calibration.winches.size());
  for (int i = 0; i < n; ++i) {
    centre += calibration.winches[i].anchor_world / n;
    if (i < kCableCount) payout += (rest.encoder_m[i] - calibration.winches[i].offset_m) / n;
  }
  double horizontal = 0.0;
  for (int i = 0; i < n; ++i) horizontal += (calibration.winches[i].anchor_world - centre).head<2>().norm() / n;
  Pose pose;
  pose.position_world = centre;
  if (payout > horizontal) pose.position_world.z() -= std::sqrt(payout * payout - horizontal * horizontal);
  return pose;
}

Eigen::Matrix<double, 6, 1> pose_difference(const Pose& measured, const Pose& estimate) {
  Eigen::Matrix<double, 6, 1> d;
  d.head<3>() = measured.position_world - estimate.position_world;
  d.tail<3>() = so3_log(measured.world_R_platform.normalized() * estimate.world_R_platform.normalized().conjugate());
  return d;
}

double mahalanobis_squared(const Eigen::Matrix<double, 6, 1>& difference,
                           const Eigen::Matrix<double, 6, 6>& covariance) {
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(covariance);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || ldlt.vectorD().minCoeff() <= 0.0) {
    return std::numeric_limits<double>::infinity();
  }
  return difference.dot(ldlt.solve(difference));
}

}  // namespace cdpr
