// The closed-form columns of terms absent from a base catenary fit against
// EffectPoseFactor's own Jacobian blocks with every term at 0.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/calibration/absent_term_columns.h"
#include "solver/calibration/effect_pose_factor.h"
#include "solver/model/initial_guess.h"
#include "../model/test_robots.h"

namespace cdpr {
namespace {

void expect_factor_columns(const Robot& robot, const Eigen::Vector3d& position, Sample sample, const Loss& loss) {
  constexpr int kRows = EffectPoseFactor::kResidualDim;
  const Pose pose = test::tilted_pose(position);
  const auto anchors = test::anchors_of(robot);
  const auto force = refine_reference_force(robot, anchors, sample,
                                            paper_reference_force_guess(robot, anchors, sample), 1e-3);
  ASSERT_TRUE(force.has_value());
  const std::array<double, kCableCount> offsets = {-2.0, -0.5, 1.0, 2.5};
  const std::vector<Effect> effects(kAllEffects.begin(), kAllEffects.end());

  // The factor's blocks in keys() order: pose, force, anchors, offsets, then the terms at 0.
  std::vector<std::vector<double>> values = {
      {pose.position_world.x(), pose.position_world.y(), pose.position_world.z(), pose.world_R_platform.w(),
       pose.world_R_platform.x(), pose.world_R_platform.y(), pose.world_R_platform.z()},
      {force->x(), force->y()}};
  std::vector<int> dims = {6, 2};
  for (int i = 0; i < kCableCount; ++i) {
    values.push_back({anchors[i].x(), anchors[i].y(), anchors[i].z()});
    dims.push_back(3);
  }
  for (int i = 0; i < kCableCount; ++i) {
    values.push_back({offsets[i]});
    dims.push_back(1);
  }
  for (Effect e : effects) {
    values.emplace_back(effect_dimension(e), 0.0);
    dims.push_back(effect_dimension(e));
  }
  std::vector<const double*> parameters;
  std::vector<std::vector<double>> factor_blocks, closed_form;
  std::vector<double*> factor_jacobians, closed_jacobians;
  for (std::size_t b = 0; b < values.size(); ++b) {
    parameters.push_back(values[b].data());
    factor_blocks.emplace_back(kRows * dims[b], 0.0);
  }
  for (auto& b : factor_blocks) factor_jacobians.push_back(b.data());
  for (Effect e : effects) closed_form.emplace_back(kRows * effect_dimension(e), 0.0);
  for (auto& b : closed_form) closed_jacobians.push_back(b.data());

  const EffectPoseFactor factor(robot, 0, sample, 1e-3, loss, effects);
  std::array<double, kRows> residual;
  double cost = 0.0;
  ASSERT_TRUE(factor.evaluate(parameters.data(), residual.data(), factor_jacobians.data(), &cost));
  const Eigen::Vector2d reference_force = *force;
  ASSERT_TRUE(absent_term_jacobians(robot, {sample, pose, reference_force, anchors, offsets}, 1e-3, loss, effects,
                                    closed_jacobians.data()));
  const std::size_t first_effect = 2 + 2 * kCableCount;
  for (std::size_t j = 0; j < effects.size(); ++j) {
    const std::vector<double>& expected = factor_blocks[first_effect + j];
    for (std::size_t k = 0; k < expected.size(); ++k) {
      EXPECT_NEAR(closed_form[j][k], expected[k], 1e-9 * (1.0 + std::abs(expected[k])))
          << effect_model_name(effects[j]) << " entry " << k;
    }
  }
}

// GIVEN a base catenary row, THEN each absent term's closed-form columns are the factor's.
TEST(AbsentTermColumns, MatchTheFactorWithEveryTermAtZeroLargeRobot) {
  const Robot robot = test::large_robot();
  expect_factor_columns(robot, {100, 80, 12}, test::sample_at(test::tilted_pose({100, 80, 12})), Loss{});
}

TEST(AbsentTermColumns, MatchTheFactorWithEveryTermAtZeroSmallRobot) {
  const Robot robot = test::small_robot();
  expect_factor_columns(robot, {5, 2, 8}, test::sample_at(test::tilted_pose({5, 2, 8})), Loss{});
}

// GIVEN readings beyond a Huber width and one left out, THEN the columns are scaled and zeroed as the factor's.
TEST(AbsentTermColumns, FollowTheLossAndTheReadingsLeftOut) {
  const Robot robot = test::large_robot();
  Sample sample = test::sample_at(test::tilted_pose({100, 80, 12}));
  sample.encoder_left_out[2] = true;
  expect_factor_columns(robot, {100, 80, 12}, sample, Loss{1.0});
}

}  // namespace
}  // namespace cdpr
