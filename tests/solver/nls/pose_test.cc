#include "solver/nls/pose.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace cdpr {
namespace {

Eigen::Vector3d random_axis(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
}

// Rotation angle between two quaternions [rad], independent of so3_log.
double angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b);
}

TEST(Pose, SkewIsCrossProduct) {
  // GIVEN two vectors; THEN skew(a) b == a x b
  const Eigen::Vector3d a(0.3, -1.2, 2.0), b(-0.7, 0.4, 1.1);
  EXPECT_LT((skew(a) * b - a.cross(b)).norm(), 1e-15);
}

TEST(Pose, ExpMatchesAngleAxisOverTheWholeRange) {
  std::mt19937 rng(1);
  for (double angle : {0.0, 1e-12, 1e-7, 1e-5, 1e-3, 0.5, 2.0, M_PI - 1e-6, M_PI}) {
    // GIVEN a rotation vector of known angle and axis
    const Eigen::Vector3d axis = random_axis(rng);
    // WHEN exponentiated; THEN it is that rotation
    const Eigen::Quaterniond q = so3_exp(angle * axis);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_LT(angle_between(q, Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis))), 1e-14) << angle;
  }
}

TEST(Pose, LogInvertsExpNearZeroAndNearPi) {
  std::mt19937 rng(2);
  for (double angle : {0.0, 1e-12, 1e-7, 1e-5, 1e-3, 0.5, 2.0, 3.0, M_PI - 1e-4, M_PI - 1e-9}) {
    // GIVEN a rotation vector with angle in [0, pi)
    const Eigen::Vector3d v = angle * random_axis(rng);
    // WHEN log(exp(v)); THEN v comes back, relative to its size
    const Eigen::Vector3d back = so3_log(so3_exp(v));
    EXPECT_LT((back - v).norm(), 1e-12 * std::max(1.0, angle)) << angle;
  }
}

TEST(Pose, LogPicksTheShortRotationForNegatedQuaternion) {
  // GIVEN -q, the same rotation as q
  const Eigen::Vector3d v(0.2, -0.1, 0.3);
  Eigen::Quaterniond q = so3_exp(v);
  q.coeffs() = -q.coeffs();
  // THEN the log is still v (angle in [0, pi])
  EXPECT_LT((so3_log(q) - v).norm(), 1e-14);
}

TEST(Pose, LogAtExactlyPiHasAngleHalfTurn) {
  // GIVEN a half turn about an axis; THEN |log| == pi along +-axis
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d v = so3_log(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, axis)));
  EXPECT_NEAR(v.norm(), M_PI, 1e-12);
  EXPECT_NEAR(std::abs(v.normalized().dot(axis)), 1.0, 1e-12);
}

TEST(Pose, RightJacobianInverseMatchesNumericDifferentiationOfLog) {
  std::mt19937 rng(3);
  for (double angle : {0.0, 1e-6, 0.3, 1.5, 2.8}) {
    // GIVEN phi = log(R); WHEN perturbing R on the right by Exp(d)
    const Eigen::Vector3d phi = angle * random_axis(rng);
    const Eigen::Quaterniond R = so3_exp(phi);
    Eigen::Matrix3d numeric;
    const double h = 1e-6;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(j);
      numeric.col(j) = (so3_log(R * so3_exp(d)) - so3_log(R * so3_exp(-d))) / (2.0 * h);
    }
    // THEN d log / d d == Jr^-1(phi)
    EXPECT_LT((so3_right_jacobian_inverse(phi) - numeric).cwiseAbs().maxCoeff(), 1e-8) << angle;
  }
}

TEST(Pose, RetractAddsPositionAndRotatesOnTheRight) {
  // GIVEN a pose and a tangent step (d_p, d_theta)
  Pose pose;
  pose.position_world = Eigen::Vector3d(1, 2, 3);
  pose.world_R_platform = so3_exp(Eigen::Vector3d(0.1, 0.7, -0.2));
  const Pose before = pose;
  const double step[6] = {0.5, -0.25, 0.125, 0.0, 0.0, 0.3};
  // WHEN retracted
  retract(pose, step);
  // THEN position moved by d_p and R = R0 * Exp(d_theta) (platform-frame z turn)
  EXPECT_LT((pose.position_world - Eigen::Vector3d(1.5, 1.75, 3.125)).norm(), 1e-15);
  const Eigen::Quaterniond expected = before.world_R_platform * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  EXPECT_LT(angle_between(pose.world_R_platform, expected), 1e-14);
  EXPECT_NEAR(pose.world_R_platform.norm(), 1.0, 1e-15);
}

TEST(Pose, TransformMovesPlatformPointsIntoTheWorld) {
  // GIVEN a quarter turn about z and an offset; THEN x_platform lands on y_world + offset
  Pose pose;
  pose.position_world = Eigen::Vector3d(10, 0, 0);
  pose.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  EXPECT_LT((pose.transform(Eigen::Vector3d::UnitX()) - Eigen::Vector3d(10, 1, 0)).norm(), 1e-15);
}

}  // namespace
}  // namespace cdpr
