// The pose factor with model terms: each effect's analytic Jacobian against
// central differences, and the no-effect case against the base factor.
#include <gtest/gtest.h>

#include "../nls/numeric_jacobian.h"
#include "solver/calibration/effect_pose_factor.h"
#include "solver/model/initial_guess.h"
#include "solver/calibration/static_pose_factor.h"
#include "../model/test_robots.h"

namespace cdpr {
namespace {

// A value of each effect's parameter at a realistic size (solver/model/effects.h units).
std::vector<double> effect_value(Effect e) {
  switch (e) {
    case Effect::kElasticity: return {0.67};  // EA = 1.5e6 N
    case Effect::kEncoderScale: return {0.003, -0.002, 0.001, 0.004};
    case Effect::kLoadCell: return {15.0, 0.02};
    case Effect::kComOffset: return {0.05, -0.03, 0.02};
    case Effect::kDensityError: return {0.05};
    case Effect::kPulleyRadius: return {0.15};
    case Effect::kLoadCellBias: return {15.0};
    case Effect::kPoseReferenceOffset: return {0.04, -0.03, 0.05};
  }
  return {};
}

struct PoseSetup {
  Pose pose;
  Sample sample;
  Eigen::Vector2d force;
};

PoseSetup setup_for(const Robot& robot, const Eigen::Vector3d& position) {
  PoseSetup s;
  s.pose = test::tilted_pose(position);
  s.sample = test::sample_at(s.pose);
  const auto anchors = test::anchors_of(robot);
  const auto force = refine_reference_force(robot, anchors, s.sample,
                                            paper_reference_force_guess(robot, anchors, s.sample), 1e-3);
  EXPECT_TRUE(force.has_value());
  s.force = force.value_or(Eigen::Vector2d(100.0, 100.0));
  return s;
}

std::vector<test::TestVariable> variables(const Robot& robot, const PoseSetup& s, const std::vector<Effect>& effects) {
  std::vector<test::TestVariable> vars = {test::pose_variable(s.pose.position_world, s.pose.world_R_platform),
                                          test::vector_variable({s.force.x(), s.force.y()})};
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d a = robot.winches[i].anchor_world + Eigen::Vector3d(0.3 * i, -0.2, 0.1 * i);
    vars.push_back(test::vector_variable({a.x(), a.y(), a.z()}));
  }
  for (int i = 0; i < kCableCount; ++i) vars.push_back(test::vector_variable({1.5 * i - 2.0}));
  for (Effect e : effects) vars.push_back(test::vector_variable(effect_value(e)));
  return vars;
}

void check_effects(const Robot& robot, const Eigen::Vector3d& position, const std::vector<Effect>& effects) {
  const PoseSetup s = setup_for(robot, position);
  const EffectPoseFactor factor(robot, 0, s.sample, 1e-3, Loss{}, effects);
  test::expect_jacobians_match(factor, variables(robot, s, effects), 1e-6, 1e-5);
}

class EachEffect : public ::testing::TestWithParam<Effect> {};

TEST_P(EachEffect, JacobianMatchesNumericLargeRobot) { check_effects(test::large_robot(), {100, 80, 12}, {GetParam()}); }
TEST_P(EachEffect, JacobianMatchesNumericSmallRobot) { check_effects(test::small_robot(), {5, 2, 8}, {GetParam()}); }

INSTANTIATE_TEST_SUITE_P(Effects, EachEffect, ::testing::ValuesIn(kAllEffects),
                         [](const ::testing::TestParamInfo<Effect>& info) {
                           return std::string(effect_model_name(info.param));
                         });

TEST(EffectPoseFactor, JacobianMatchesNumericWithAllEffectsTogether) {
  check_effects(test::large_robot(), {140, 120, 18}, {kAllEffects.begin(), kAllEffects.end()});
}

TEST(EffectPoseFactor, WithoutEffectsEqualsTheBaseFactor) {
  const Robot robot = test::large_robot();
  const PoseSetup s = setup_for(robot, {100, 80, 12});
  const EffectPoseFactor with_effects(robot, 0, s.sample, 1e-3, Loss{}, {});
  const StaticPoseFactor base(robot, 0, s.sample, 1e-3, Loss{});
  const auto vars = variables(robot, s, {});
  std::vector<const double*> params;
  for (const auto& v : vars) params.push_back(v.ambient.data());
  std::array<double, EffectPoseFactor::kResidualDim> r1, r2;
  double c1 = 0.0, c2 = 0.0;
  ASSERT_TRUE(with_effects.evaluate(params.data(), r1.data(), nullptr, &c1));
  ASSERT_TRUE(base.evaluate(params.data(), r2.data(), nullptr, &c2));
  for (int j = 0; j < EffectPoseFactor::kResidualDim; ++j) EXPECT_NEAR(r1[j], r2[j], 1e-6) << "residual " << j;
}

// GIVEN a 15 N load-cell bias in the model, THEN the predicted reading moves by 15 N.
TEST(EffectPoseFactor, PredictionReportsPhysicalResiduals) {
  const Robot robot = test::large_robot();
  const PoseSetup s = setup_for(robot, {100, 80, 12});
  const EffectPoseFactor factor(robot, 0, s.sample, 1e-3, Loss{}, {Effect::kLoadCell});
  auto vars = variables(robot, s, {Effect::kLoadCell});
  std::vector<const double*> params;
  for (const auto& v : vars) params.push_back(v.ambient.data());
  PosePrediction with_bias;
  ASSERT_TRUE(factor.predict(params.data(), with_bias));
  vars.back().ambient = {0.0, 0.02};
  params.back() = vars.back().ambient.data();
  PosePrediction without;
  ASSERT_TRUE(factor.predict(params.data(), without));
  EXPECT_NEAR(with_bias.force_residual_n - without.force_residual_n, 15.0, 1e-9);
}

// GIVEN a row carrying its own sigmas, THEN its reading rows are whitened by
// them instead of robot.toml's, in both pose factors.
TEST(PoseFactors, ARowsOwnSigmasSetItsWeight) {
  const Robot robot = test::large_robot();
  const PoseSetup s = setup_for(robot, {100, 80, 12});
  Sample own = s.sample;
  own.sigma = SampleSigmas{{robot.noise.encoder_m / 10.0, robot.noise.encoder_m / 2.0, robot.noise.encoder_m,
                            robot.noise.encoder_m * 4.0},
                           robot.noise.force_n / 5.0, robot.noise.position_m, robot.noise.orientation_rad};
  const auto vars = variables(robot, s, {});
  std::vector<const double*> params;
  for (const auto& v : vars) params.push_back(v.ambient.data());
  const auto residuals = [&](const Factor& factor) {
    std::array<double, EffectPoseFactor::kResidualDim> r;
    double cost = 0.0;
    EXPECT_TRUE(factor.evaluate(params.data(), r.data(), nullptr, &cost));
    return r;
  };
  const auto check = [&](const Factor& robot_weighted, const Factor& row_weighted) {
    const auto r_robot = residuals(robot_weighted);
    const auto r_row = residuals(row_weighted);
    for (int i = 0; i < kCableCount; ++i) {
      EXPECT_NEAR(r_row[i], r_robot[i] * robot.noise.encoder_m / own.sigma.encoder_m[i], 1e-9 * std::abs(r_row[i]))
          << "encoder " << i;
      EXPECT_EQ(r_row[kCableCount + i], r_robot[kCableCount + i]) << "height " << i;  // not a reading
    }
    const int force = 2 * kCableCount;
    EXPECT_NEAR(r_row[force], r_robot[force] * 5.0, 1e-9 * std::abs(r_row[force]));
  };
  check(StaticPoseFactor(robot, 0, s.sample, 1e-3, Loss{}), StaticPoseFactor(robot, 0, own, 1e-3, Loss{}));
  check(EffectPoseFactor(robot, 0, s.sample, 1e-3, Loss{}, {}), EffectPoseFactor(robot, 0, own, 1e-3, Loss{}, {}));
}

}  // namespace
}  // namespace cdpr
