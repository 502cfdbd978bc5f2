// The LM tests' own factors (and with them SizedFactor's maps and loss) have
// Jacobians matching central differences.
#include <gtest/gtest.h>

#include "lm_test_factors.h"
#include "numeric_jacobian.h"

namespace cdpr::test {
namespace {

Pose some_pose(double seed) {
  Pose p;
  p.position_world = Eigen::Vector3d(1.0 + seed, -2.0, 0.5 * seed);
  p.world_R_platform = so3_exp(Eigen::Vector3d(0.3, -0.2 * seed, 0.9));
  return p;
}
TestVariable pose_var(const Pose& p) { return pose_variable(p.position_world, p.world_R_platform); }

TEST(LmTestFactors, SE3PriorJacobianMatchesNumeric) {
  const SE3PriorFactor f(PoseKey(0), some_pose(1.0), 0.01, 0.02);
  expect_jacobians_match(f, {pose_var(some_pose(1.7))}, 1e-6, 1e-6);
}

TEST(LmTestFactors, SE3BetweenJacobianMatchesNumeric) {
  const SE3BetweenFactor f(PoseKey(0), PoseKey(1), some_pose(0.3), 0.01, 0.02);
  expect_jacobians_match(f, {pose_var(some_pose(1.1)), pose_var(some_pose(2.4))}, 1e-6, 1e-6);
}

TEST(LmTestFactors, RangeJacobianMatchesNumeric) {
  const RangeFactor f(PoseKey(0), AnchorKey(0), OffsetKey(0), {0.5, -0.3, 0.2}, 12.0, 0.001);
  expect_jacobians_match(f, {pose_var(some_pose(0.5)), vector_variable({8.0, 3.0, 9.0}), vector_variable({0.2})},
                         1e-6, 1e-6);
}

TEST(LmTestFactors, StackedRangesJacobianMatchesNumericAndKeepsToItsRows) {
  const std::array<Eigen::Vector3d, 4> attachments = {
      {{0.5, -0.3, 0.2}, {-0.5, -0.3, 0.2}, {-0.5, 0.3, 0.2}, {0.5, 0.3, 0.2}}};
  const std::array<double, 8> encoders = {12.0, 12.01, 11.0, 11.02, 13.0, 12.99, 12.5, 12.51};
  std::vector<TestVariable> variables = {pose_var(some_pose(0.5)), vector_variable({8.0, 3.0, 9.0}),
                                         vector_variable({-4.0, 3.0, 9.5}), vector_variable({-4.0, -6.0, 9.0}),
                                         vector_variable({8.5, -6.0, 8.0})};
  for (double offset : {0.2, -0.1, 0.0, 0.3}) variables.push_back(vector_variable({offset}));
  expect_jacobians_match(StackedRangesFactor<2>(0, attachments, encoders, 0.001), variables, 1e-6, 1e-6);
  // every residual beyond the Huber width
  expect_gradient_matches_cost(StackedRangesFactor<2>(0, attachments, encoders, 0.001, Loss{2.0}), variables, 1e-7,
                               1e-5);
}

TEST(LmTestFactors, RangeWithActiveHuberJacobianMatchesNumericOfScaledResidual) {
  // GIVEN a residual far beyond the Huber width: the factor returns s*r and s*J
  // with s frozen at the point (Ceres' corrector), so compare cost gradients.
  const RangeFactor f(PoseKey(0), AnchorKey(0), OffsetKey(0), {0.5, -0.3, 0.2}, 12.0, 0.001, Loss{2.0});
  expect_gradient_matches_cost(f, {pose_var(some_pose(0.5)), vector_variable({8.0, 3.0, 9.0}), vector_variable({0.2})},
                               1e-7, 1e-5);
}

TEST(LmTestFactors, CurveLineLogAndLinearJacobiansMatchNumeric) {
  int refusals = 0;
  expect_jacobians_match(ExpCurveFactor(EffectKey(0), 0.7, 2.0), {vector_variable({0.3, 0.1})}, 1e-6, 1e-7);
  expect_jacobians_match(LineFactor(EffectKey(0), 0.7, 2.0, 0.1, Loss{}), {vector_variable({0.3, 0.1})}, 1e-6, 1e-7);
  expect_jacobians_match(LogFactor(EffectKey(0), 2.0, 0.5, &refusals), {vector_variable({0.7})}, 1e-6, 1e-7);
  const LinearFactor linear(EffectKey(0), EffectKey(1), Eigen::Matrix2d::Random(), Eigen::Matrix2d::Random(),
                            Eigen::Vector2d(1, 2), 0.3);
  expect_jacobians_match(linear, {vector_variable({0.3, 0.1}), vector_variable({-1, 2})}, 1e-6, 1e-7);
  EXPECT_EQ(refusals, 0);
}

}  // namespace
}  // namespace cdpr::test
