// The noise each sensor group implies at a fit (solver/calibration/
// noise_components.h): the redundancies share out the degrees of freedom,
// noise as stated gives scales near 1, and an orientation twice as noisy as
// robot.toml says is measured as such.
#include <algorithm>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "solver/calibration/calibrate.h"
#include "solver/calibration/noise_components.h"

namespace cdpr {
namespace {

sim::SimulatedDataset noise_data(std::uint64_t seed, double orientation_factor) {
  sim::DatasetConfig config;
  config.pose_count = 30;
  config.seed = seed;
  config.anchor_perturbation_m = 2.0;
  config.segments = 200;
  config.orientation_noise_factor = orientation_factor;
  auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data) << (data ? "" : data.error());
  return data ? std::move(*data) : sim::SimulatedDataset{};
}

const NoiseComponent& group(const std::vector<NoiseComponent>& noise, NoiseGroup g) {
  const auto at = std::find_if(noise.begin(), noise.end(), [&](const NoiseComponent& c) { return c.group == g; });
  EXPECT_NE(at, noise.end()) << noise_group_name(g);
  static const NoiseComponent none;
  return at == noise.end() ? none : *at;
}

TEST(NoiseComponents, RedundanciesAddUpToTheDegreesOfFreedom) {
  // GIVEN a fit of clean data
  const sim::SimulatedDataset data = noise_data(1, 1.0);
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  // WHEN its noise components are taken (calibrate() keeps them)
  // THEN every group is there, and the redundancies sum to rows - unknowns (the hat matrix's trace)
  ASSERT_EQ(result.noise.size(), static_cast<std::size_t>(kNoiseGroupCount));
  double redundancy = 0.0, chi_square = 0.0;
  for (const NoiseComponent& c : result.noise) {
    redundancy += c.redundancy;
    chi_square += c.chi_square;
    EXPECT_GT(c.redundancy, 0.0) << noise_group_name(c.group);
    EXPECT_LE(c.redundancy, c.rows) << noise_group_name(c.group);
  }
  EXPECT_NEAR(redundancy, result.degrees_of_freedom, 1e-6 * result.degrees_of_freedom);
  EXPECT_NEAR(chi_square, result.chi_square, 1e-6 * result.chi_square);
}

TEST(NoiseComponents, NoiseAsStatedGivesScalesNearOne) {
  // GIVEN clean data whose noise is what robot.toml states
  const sim::SimulatedDataset data = noise_data(2, 1.0);
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  // THEN the sensor groups' scales are near 1 and none is noisier than stated at 1e-3
  for (NoiseGroup g : {NoiseGroup::kEncoder, NoiseGroup::kLoadCell, NoiseGroup::kPosition, NoiseGroup::kOrientation}) {
    const NoiseComponent& c = group(result.noise, g);
    EXPECT_GT(c.scale, 0.6) << noise_group_name(g);
    EXPECT_LT(c.scale, 1.4) << noise_group_name(g);
    EXPECT_GT(c.p_high, 1e-3) << noise_group_name(g);
  }
}

TEST(NoiseComponents, AnOrientationTwiceAsNoisyIsMeasured) {
  // GIVEN data whose orientation noise is twice robot.toml's sigma
  const sim::SimulatedDataset data = noise_data(3, 2.0);
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  // THEN the orientation's scale is about 2, far beyond the noise, and the readings' stay near 1
  const NoiseComponent& orientation = group(result.noise, NoiseGroup::kOrientation);
  EXPECT_GT(orientation.scale, 1.6);
  EXPECT_LT(orientation.scale, 2.5);
  EXPECT_LT(orientation.p_high, 1e-6);
  EXPECT_GT(orientation.likelihood_gain, 20.0);
  EXPECT_LT(group(result.noise, NoiseGroup::kEncoder).scale, 1.4);
}

}  // namespace
}  // namespace cdpr
