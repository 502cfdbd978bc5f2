// The waypoints that tell mimicking model terms apart (sim/discriminating_poses.h)
// and the rows cdpr-sim measures there (DatasetConfig::extra_positions).
#include "sim/discriminating_poses.h"

#include <gtest/gtest.h>

#include "sim/dataset.h"

namespace cdpr::sim {
namespace {

DatasetConfig gain_data(int poses) {
  DatasetConfig c;
  c.preset = Preset::kLarge;
  c.pose_count = poses;
  c.seed = 11;
  c.effects.force_gain = 0.03;
  c.segments = 400;
  return c;
}

// A fit that is the truth itself, with one term's values changed.
Calibration truth_fit(const SimulatedDataset& data, const EffectValues& effects) {
  Calibration c;
  for (const WinchTruth& w : data.truth.winches) {
    WinchCalibration winch;
    winch.anchor_world = w.anchor_world;
    winch.offset_m = w.offset_m;
    c.winches.push_back(winch);
  }
  c.effects = effects;
  return c;
}

MimicSet gain_or_bias(const SimulatedDataset& data, double bias_n, double gain) {
  MimicSet set;
  MimicMember as_gain;
  as_gain.effect = Effect::kLoadCell;
  as_gain.fit = truth_fit(data, {{"force_gain", {gain}}});
  MimicMember as_bias;
  as_bias.effect = Effect::kLoadCellBias;
  as_bias.fit = truth_fit(data, {{"force_bias", {bias_n}}});
  set.members = {as_gain, as_bias};
  return set;
}

TEST(DiscriminatingPoses, TheTruthPredictsItsOwnNoiselessRows) {
  // GIVEN noiseless rows of a robot with a 3 % load-cell gain
  DatasetConfig config = gain_data(12);
  config.noise_scale = 0.0;
  auto data = simulate_dataset(config);
  ASSERT_TRUE(data) << data.error();
  // WHEN two members that are both the truth predict them
  const MimicSet same = gain_or_bias(*data, 0.0, 0.03);
  MimicSet both_truth = same;
  both_truth.members[1] = both_truth.members[0];
  DiscriminationOptions small_grid;
  small_grid.grid_xy = 3;
  small_grid.grid_z = 2;
  const DiscriminatingPoses poses =
      discriminating_poses(data->nominal, data->nominal.noise, data->samples, both_truth, small_grid);
  // THEN they agree everywhere: nothing separates a model from itself
  EXPECT_LT(poses.measured_separation_sigma, 1e-6);
  ASSERT_FALSE(poses.waypoints.empty());
  EXPECT_LT(poses.waypoints.front().separation_sigma, 1e-6);
}

TEST(DiscriminatingPoses, GainAndBiasThatAgreeOnTheMeasuredPosesDifferWhereTheTensionDiffers) {
  // GIVEN a gain and a bias that read the same at the mean reference tension of the measured poses
  auto data = simulate_dataset(gain_data(12));
  ASSERT_TRUE(data) << data.error();
  const double gain = 0.03;
  double mean_tension = 0.0;
  for (const Equilibrium& s : data->states) mean_tension += s.cables[data->nominal.reference_cable].tension_n;
  mean_tension /= static_cast<double>(data->states.size());
  const MimicSet set = gain_or_bias(*data, gain * mean_tension, gain);
  // WHEN waypoints are chosen
  DiscriminationOptions options;
  options.count = 4;
  options.grid_xy = 5;
  options.grid_z = 3;
  const DiscriminatingPoses poses = discriminating_poses(data->nominal, data->nominal.noise, data->samples, set, options);
  // THEN there are 4, best first, apart from each other, each separating the two more than the average pose
  ASSERT_EQ(poses.waypoints.size(), 4u) << poses.message;
  EXPECT_EQ(poses.candidates, 75);
  for (std::size_t k = 1; k < poses.waypoints.size(); ++k) {
    EXPECT_LE(poses.waypoints[k].separation_sigma, poses.waypoints[k - 1].separation_sigma);
    for (std::size_t j = 0; j < k; ++j) {
      EXPECT_GT((poses.waypoints[k].position_world - poses.waypoints[j].position_world).norm(), 1.0);
    }
  }
  EXPECT_GT(poses.waypoints.back().separation_sigma, 0.5);
}

TEST(DiscriminatingPoses, AMimicSetWithOneFitHasNoWaypointsAndSaysWhy) {
  auto data = simulate_dataset(gain_data(6));
  ASSERT_TRUE(data) << data.error();
  MimicSet set = gain_or_bias(*data, 10.0, 0.03);
  set.members[1].fit = Calibration{};  // a noise member without a fit
  const DiscriminatingPoses poses =
      discriminating_poses(data->nominal, data->nominal.noise, data->samples, set, DiscriminationOptions{});
  EXPECT_TRUE(poses.waypoints.empty());
  EXPECT_NE(poses.message.find("fewer than two"), std::string::npos) << poses.message;
}

TEST(SimDataset, ExtraPositionsAreMeasuredAfterTheRegularRowsWhichStayTheSame) {
  // GIVEN a data set, and the same with two extra positions
  const DatasetConfig plain = gain_data(6);
  DatasetConfig extended = plain;
  extended.extra_positions = {Eigen::Vector3d(110.0, 95.0, 20.0), Eigen::Vector3d(130.0, 120.0, 25.0)};
  auto a = simulate_dataset(plain);
  auto b = simulate_dataset(extended);
  ASSERT_TRUE(a && b);
  // THEN the regular rows are identical and the extra ones follow at the given positions (yaw 0)
  ASSERT_EQ(b->samples.size(), 8u);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(a->samples[k].encoder_m, b->samples[k].encoder_m);
  EXPECT_EQ(b->samples[6].id, 6);
  EXPECT_NEAR((b->states[7].world_T_platform.position_world - extended.extra_positions[1]).norm(), 0.0, 1e-9);
  EXPECT_NEAR(b->states[7].yaw_rad, 0.0, 1e-12);
}

TEST(SimDataset, AnExtraPositionWithoutATautRestIsAnErrorNamingIt) {
  DatasetConfig config = gain_data(3);
  config.extra_positions = {Eigen::Vector3d(110.0, 95.0, 20.0), Eigen::Vector3d(110.0, 95.0, 500.0)};
  auto data = simulate_dataset(config);
  ASSERT_FALSE(data);
  EXPECT_NE(data.error().find("extra position 2"), std::string::npos) << data.error();
}

}  // namespace
}  // namespace cdpr::sim
