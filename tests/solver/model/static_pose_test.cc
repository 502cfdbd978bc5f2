// The rest-pose solve: the equilibrium it returns and how it fails.
#include "solver/model/static_pose.h"

#include <string>

#include <gtest/gtest.h>

#include "solver/model/cable_prediction.h"
#include "test_robots.h"

namespace cdpr {
namespace {

TEST(StaticPose, RestPoseBalancesTheWeightAndReachesEveryAttachment) {
  // GIVEN the large robot and a position off-centre
  const Robot robot = test::large_robot();
  const Eigen::Vector3d position(80.0, 140.0, 20.0);
  // WHEN its rest pose is solved
  std::string why;
  const auto rest = solve_static_pose(robot, nominal_anchors(robot), position, &why);
  // THEN the cables carry the platform's weight vertically and every catenary ends at its attachment
  ASSERT_TRUE(rest) << why;
  const auto cables = predict_cables(robot, nominal_anchors(robot), rest->world_T_platform, rest->reference_force);
  ASSERT_TRUE(cables.has_value());
  double lift_n = 0.0;
  for (int i = 0; i < kCableCount; ++i) {
    lift_n += (*cables)[i].f_v_n;
    const double attachment_z = rest->world_T_platform.transform(robot.winches[i].attachment_platform).z();
    EXPECT_NEAR((*cables)[i].end_height_m, attachment_z, 1e-6);
    // AND a sagging cable is longer than its chord
    const double chord_m =
        (rest->world_T_platform.transform(robot.winches[i].attachment_platform) - robot.winches[i].anchor_world).norm();
    EXPECT_GT(rest->arc_length_m[i], chord_m);
    EXPECT_LT(rest->arc_length_m[i], 1.05 * chord_m);
  }
  EXPECT_NEAR(lift_n, robot.platform_mass_kg * robot.gravity_mps2, 1e-6 * lift_n);
  EXPECT_EQ(rest->world_T_platform.position_world, position);
  EXPECT_LT(rest->height_residual_m, 1e-6);
}

TEST(StaticPose, APositionAboveTheAnchorsHasNoRestPoseAndSaysWhy) {
  // GIVEN a position above every anchor, where cables would have to push
  const Robot robot = test::large_robot();
  const Eigen::Vector3d position(120.0, 110.0, 80.0);
  // WHEN its rest pose is solved THEN there is none, with a reason
  std::string why;
  EXPECT_FALSE(solve_static_pose(robot, nominal_anchors(robot), position, &why));
  EXPECT_FALSE(why.empty());
}

TEST(StaticPose, AnyOtherThanFourCablesIsRefused) {
  Robot robot = test::large_robot();
  robot.winches.pop_back();
  std::string why;
  EXPECT_FALSE(solve_static_pose(robot, nominal_anchors(test::large_robot()), Eigen::Vector3d(80.0, 140.0, 20.0), &why));
  EXPECT_NE(why.find("4 cables"), std::string::npos);
}

}  // namespace
}  // namespace cdpr
