#pragma once
// The platform pose from the cables (forward kinematics with sag): the
// paper's outlook, the calibration factor graph with the calibration as
// priors and the pose unknown. One rest (a samples.csv row: encoders and the
// load cell) gives the encoder (Eq. 14), attachment-height (Eq. 15) and
// reference-force (Eq. 16) residuals of solver/calibration/static_pose_factor.h,
// 9 rows, over the pose (6) and the reference cable's force (2): one row of
// redundancy, so the statics of Eq. (5)-(11) fix all six degrees of freedom,
// the yaw the weakest.
//
// The calibration's anchors, offsets and model terms are priors of their own
// sigmas (or held constant), so the covariance includes what the
// calibration does not know. The row's measured pose is not used unless
// asked (it is what the pose from the cables is checked against).
//
// Pure numerics: no I/O, no clocks. Allocates (a small problem per call).

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "solver/nls/pose.h"

namespace cdpr {

struct LocalizeOptions {
  // Sigma of the attachment-height consistency, Eq. (15) (as the calibration's fit).
  double height_sigma_m = 1e-2;
  // The calibration as priors of its sigmas (true) or exact (false).
  bool calibration_priors = true;
  // With priors: the joint covariance of the anchors and offsets
  // (calibration_covariance.h) instead of their per-axis sigmas, which
  // ignore how their errors cancel along each cable.
  std::optional<Eigen::Matrix<double, 4 * kCableCount, 4 * kCableCount>> calibration_covariance;
  // Also weight the row's measured pose (its position and orientation sigmas).
  bool use_measured_pose = false;
  int max_iterations = 50;
  // A solution whose chi-square (2 * cost, whitened) exceeds this is no
  // equilibrium of the readings: the cables cannot hold the platform where
  // the encoders say (with one row of redundancy chi-square is ~1).
  double max_chi_square = 400.0;
};

struct LocalizedPose {
  Pose world_T_platform;
  // Covariance of (position [m], rotation vector [rad]), both in the world
  // frame: p = p_hat + d_p, R = Exp(d_theta_world) * R_hat.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Vector2d reference_force = Eigen::Vector2d::Zero();  // (f_h, f_v) of the reference cable [N]
  double cost = 0.0;  // 0.5 * chi-square of the whitened residuals
  int iterations = 0;
  bool converged = false;  // a tolerance was met (else the iteration limit)

  Eigen::Vector3d position_sigma() const { return covariance.diagonal().head<3>().cwiseSqrt(); }
  Eigen::Vector3d orientation_sigma() const { return covariance.diagonal().tail<3>().cwiseSqrt(); }
};

// The pose of `rest` (its encoders and load-cell force; its pose fields are
// ignored unless options.use_measured_pose). `start`: where to begin, e.g.
// the previous rest's pose or nominal_start(); only its orientation and a
// rough position matter (the position is first refined from the encoders
// as straight cables, then the statics are solved there). Empty when there
// is no usable answer, with *why (if given) saying why: the calibration
// cannot be used, no equilibrium near the start, no equilibrium fits the
// readings, the pose is not observable.
std::optional<LocalizedPose> localize_rest(const Robot& robot, const Calibration& calibration, const Sample& rest,
                                           const Pose& start, const LocalizeOptions& options, std::string* why);

// A start for the first rest: level, under the centre of the calibrated
// anchors, at the height the encoders' mean payout reaches as straight cables.
Pose nominal_start(const Calibration& calibration, const Sample& rest);

// The world-frame (position, rotation vector) difference of `measured` from
// `estimate`, the coordinates of LocalizedPose::covariance.
Eigen::Matrix<double, 6, 1> pose_difference(const Pose& measured, const Pose& estimate);

// The squared Mahalanobis distance of that difference under `covariance`
// (infinite when singular).
double mahalanobis_squared(const Eigen::Matrix<double, 6, 1>& difference,
                           const Eigen::Matrix<double, 6, 6>& covariance);

}  // namespace cdpr
