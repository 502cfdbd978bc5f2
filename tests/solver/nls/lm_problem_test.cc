// Problem: storage layout, retraction, and the invariants it enforces.
#include <gtest/gtest.h>

#include "lm_test_factors.h"
#include "solver/nls/problem.h"

namespace cdpr {
namespace {

TEST(Problem, StoresPosesAsSevenAmbientValuesAndVectorsAsIs) {
  // GIVEN a vector then a pose
  Problem problem;
  problem.add_vector(AnchorKey(1), Eigen::Vector3d(1, 2, 3));
  Pose pose;
  pose.position_world = Eigen::Vector3d(4, 5, 6);
  pose.world_R_platform = Eigen::Quaterniond(2.0, 0.0, 0.0, 0.0);  // not normalised on purpose
  problem.add_pose(PoseKey(0), pose);
  // THEN the flat state is x y z then p, q (w first, normalised), with tangent 3 and 6
  const std::vector<double> expected = {1, 2, 3, 4, 5, 6, 1, 0, 0, 0};
  EXPECT_EQ(problem.state(), expected);
  const auto& v = problem.variables()[problem.variable_index(PoseKey(0))];
  EXPECT_TRUE(v.is_pose);
  EXPECT_EQ(v.tangent_dim, 6);
  EXPECT_EQ(v.ambient_dim, 7);
  EXPECT_EQ(v.ambient_offset, 3);
  EXPECT_EQ(problem.variables()[0].tangent_dim, 3);
}

TEST(Problem, RetractsPosesOnTheRightAndVectorsAdditively) {
  // GIVEN a pose and a vector, and steps for each
  Problem problem;
  Pose pose;
  pose.world_R_platform = so3_exp(Eigen::Vector3d(0.2, 0.0, 0.1));
  problem.add_pose(PoseKey(0), pose);
  problem.add_vector(OffsetKey(0), Eigen::VectorXd::Constant(1, 2.0));
  const double pose_step[6] = {1, 2, 3, 0, 0.1, 0};
  const double offset_step[1] = {-0.5};
  // WHEN retracted (the pose on a copy of the state, the vector in place)
  std::vector<double> copy = problem.state();
  problem.retract(0, pose_step, copy.data());
  problem.retract(1, offset_step);
  // THEN the copy moved, the problem's pose did not; the vector moved in place
  const Pose moved = pose_from_parameters(copy.data());
  EXPECT_LT((moved.position_world - Eigen::Vector3d(1, 2, 3)).norm(), 1e-15);
  EXPECT_LT(moved.world_R_platform.angularDistance(pose.world_R_platform * so3_exp(Eigen::Vector3d(0, 0.1, 0))),
            1e-15);
  EXPECT_EQ(problem.pose(PoseKey(0)).position_world, Eigen::Vector3d::Zero());
  EXPECT_EQ(problem.vector(OffsetKey(0))(0), 1.5);
}

TEST(Problem, FindsVariablesByKeyOfAnyIndex) {
  // GIVEN keys with small, large and negative indices of several kinds
  Problem problem;
  problem.add_vector(AnchorKey(3), Eigen::Vector3d(1, 2, 3));
  problem.add_pose(PoseKey(7), Pose{});
  problem.add_vector(EffectKey(-2), Eigen::VectorXd::Constant(1, 4.0));
  problem.add_vector(EffectKey(1 << 28), Eigen::VectorXd::Constant(2, 5.0));
  // THEN each is found at its position, and absent ones are not
  EXPECT_EQ(problem.variable_index(AnchorKey(3)), 0);
  EXPECT_EQ(problem.variable_index(PoseKey(7)), 1);
  EXPECT_EQ(problem.variable_index(EffectKey(-2)), 2);
  EXPECT_EQ(problem.variable_index(EffectKey(1 << 28)), 3);
  EXPECT_EQ(problem.vector(EffectKey(-2))(0), 4.0);
  EXPECT_TRUE(problem.has(PoseKey(7)));
  EXPECT_FALSE(problem.has(PoseKey(6)));
  EXPECT_FALSE(problem.has(PoseKey(70)));
  EXPECT_FALSE(problem.has(OffsetKey(0)));
  EXPECT_FALSE(problem.has(EffectKey(-3)));
}

TEST(Problem, GroupsEachPosesVariablesInOrderOfFirstAppearance) {
  // GIVEN pose 5's force before its pose, pose 2 without a force, pose 9's
  // pose before its force, a constant pose and globals in no key order
  Problem problem;
  problem.add_vector(OffsetKey(0), Eigen::VectorXd::Constant(1, 0.0));             // 0
  problem.add_vector(ReferenceForceKey(5), Eigen::Vector2d(1, 1));                  // 1
  problem.add_pose(PoseKey(2), Pose{});                                             // 2
  problem.add_vector(AnchorKey(1), Eigen::Vector3d::Zero());                        // 3
  problem.add_pose(PoseKey(9), Pose{});                                             // 4
  problem.add_pose(PoseKey(5), Pose{});                                             // 5
  problem.add_pose(PoseKey(7), Pose{});                                             // 6
  problem.add_vector(ReferenceForceKey(9), Eigen::Vector2d(1, 1));                  // 7
  problem.add_vector(AnchorKey(0), Eigen::Vector3d::Zero());                        // 8
  problem.set_constant(PoseKey(7), true);
  // WHEN ordered for elimination
  const EliminationOrder order = problem.elimination_order();
  // THEN a pose and its force share a group, numbered as first met; the
  // constant pose takes no part; the globals are kept by key
  constexpr int kKept = EliminationOrder::kKept;
  EXPECT_EQ(order.group_count, 3);
  EXPECT_EQ(order.group, (std::vector<int>{kKept, 0, 1, kKept, 2, 0, kKept, 2, kKept}));
  EXPECT_EQ(order.kept, (std::vector<int>{8, 3, 0}));
}

TEST(ProblemDeathTest, RefusesFactorsOnUnknownVariables) {
  // GIVEN a factor naming a variable that was never added; THEN abort with its name
  Problem problem;
  problem.add_pose(PoseKey(0), Pose{});
  EXPECT_DEATH(problem.add_factor(std::make_unique<test::RangeFactor>(PoseKey(0), AnchorKey(3), OffsetKey(3),
                                                                      Eigen::Vector3d::Zero(), 1.0, 1.0)),
               "unknown variable anchor\\[3\\]");
}

TEST(ProblemDeathTest, RefusesDuplicateKeysAndWrongKinds) {
  Problem problem;
  problem.add_vector(AnchorKey(0), Eigen::Vector3d::Zero());
  EXPECT_DEATH(problem.add_vector(AnchorKey(0), Eigen::Vector3d::Zero()), "added twice");
  EXPECT_DEATH((void)problem.pose(AnchorKey(0)), "not a pose");
  EXPECT_DEATH(problem.set_vector(AnchorKey(0), Eigen::Vector2d::Zero()), "expected 3");
}

}  // namespace
}  // namespace cdpr
