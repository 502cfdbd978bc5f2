// Every analytic factor Jacobian against central differences (docs/STYLE.md).
#include <gtest/gtest.h>

#include "../nls/numeric_jacobian.h"
#include "solver/model/initial_guess.h"
#include "solver/calibration/pose_prior_factor.h"
#include "solver/calibration/rigid_encoder_factor.h"
#include "solver/calibration/static_pose_factor.h"
#include "../model/test_robots.h"

namespace cdpr {
namespace {

std::vector<test::TestVariable> static_pose_variables(const Robot& robot, const Pose& pose, const Eigen::Vector2d& f) {
  std::vector<test::TestVariable> vars = {test::pose_variable(pose.position_world, pose.world_R_platform),
                                          test::vector_variable({f.x(), f.y()})};
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d a = robot.winches[i].anchor_world + Eigen::Vector3d(0.3 * i, -0.2, 0.1 * i);
    vars.push_back(test::vector_variable({a.x(), a.y(), a.z()}));
  }
  for (int i = 0; i < kCableCount; ++i) vars.push_back(test::vector_variable({1.5 * i - 2.0}));
  return vars;
}

void check_static_pose_factor(const Robot& robot, const Eigen::Vector3d& position, double huber) {
  const Pose pose = test::tilted_pose(position);
  const Sample sample = test::sample_at(pose);
  const auto anchors = test::anchors_of(robot);
  const auto force = refine_reference_force(robot, anchors, sample,
                                            paper_reference_force_guess(robot, anchors, sample), 1e-3);
  ASSERT_TRUE(force.has_value());
  const StaticPoseFactor factor(robot, 0, sample, 1e-3, Loss{huber});
  if (huber > 0.0) {
    // The loss robustifies the readings only: the height rows of Eq. (15),
    // hundreds of sigmas off at this untuned point, keep their squares, so
    // the cost is ~1e8 and its central differences carry ~1e-2 of rounding.
    test::expect_gradient_matches_cost(factor, static_pose_variables(robot, pose, *force), 1e-6, 2e-4);
  } else {
    test::expect_jacobians_match(factor, static_pose_variables(robot, pose, *force), 1e-6, 1e-5);
  }
}

TEST(StaticPoseFactor, JacobianMatchesNumericLargeRobot) { check_static_pose_factor(test::large_robot(), {100, 80, 12}, 0); }
TEST(StaticPoseFactor, JacobianMatchesNumericSmallRobot) { check_static_pose_factor(test::small_robot(), {5, 2, 8}, 0); }
TEST(StaticPoseFactor, JacobianMatchesNumericWithHuberLoss) {
  check_static_pose_factor(test::large_robot(), {140, 120, 18}, 1.5);
}

TEST(PosePriorFactor, JacobianMatchesNumeric) {
  const Pose measured = test::tilted_pose({10, 20, 30});
  Pose current = measured;
  current.position_world += Eigen::Vector3d(0.01, -0.02, 0.005);
  current.world_R_platform = current.world_R_platform * Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  const PosePriorFactor factor(0, measured, 0.005, 0.01, Loss{});
  test::expect_jacobians_match(factor, {test::pose_variable(current.position_world, current.world_R_platform)}, 1e-7,
                               1e-5);
}

TEST(RigidEncoderFactor, JacobianMatchesNumeric) {
  const Pose pose = test::tilted_pose({10, 20, 30});
  const RigidEncoderFactor factor(0, 1, Eigen::Vector3d(0.5, -0.5, 0.5), 60.0, 0.01, Loss{});
  test::expect_jacobians_match(factor,
                               {test::pose_variable(pose.position_world, pose.world_R_platform),
                                test::vector_variable({50.0, 2.0, 48.0}), test::vector_variable({3.0})},
                               1e-6, 1e-5);
}

}  // namespace
}  // namespace cdpr
