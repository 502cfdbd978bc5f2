// The model terms (solver/model/effects.h) against the simulator's independent
// physics: on noiseless data with effects hidden, the fit with those terms
// reproduces every reading and recovers anchors and effect values exactly.
#include <cmath>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "solver/calibration/calibrate.h"

namespace cdpr {
namespace {

void expect_exact_recovery(const sim::DatasetConfig& config, const std::vector<Effect>& model) {
  auto data = sim::simulate_dataset(config);
  ASSERT_TRUE(data) << data.error();
  CalibrationOptions options;
  options.effects = model;
  const CalibrationResult result = calibrate(data->nominal, data->samples, options);
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_LT(result.calibration.fit.rms_encoder_m, 1e-5);
  EXPECT_LT(result.calibration.fit.rms_force_n, 1e-4);
  for (int i = 0; i < kCableCount; ++i) {
    EXPECT_LT((result.calibration.winches[i].anchor_world - data->truth.winches[i].anchor_world).norm(), 1e-4);
  }
  // Every true effect value, and 0 for the fitted terms the data do not hold.
  for (const auto& [name, fitted] : result.calibration.effects) {
    if (name.ends_with("_sigma")) continue;
    const auto truth = data->truth.effects.find(name);
    for (std::size_t j = 0; j < fitted.size(); ++j) {
      const double expected = truth == data->truth.effects.end() ? 0.0 : truth->second[j];
      EXPECT_NEAR(fitted[j], expected, 1e-4 * std::max(1.0, std::abs(expected))) << name << "[" << j << "]";
    }
  }
}

sim::DatasetConfig noiseless_large() {
  sim::DatasetConfig c;
  c.seed = 5;
  c.noise_scale = 0.0;
  return c;
}

TEST(EffectModel, ElasticityPulleyDensityAndLoadCellReproduceTheSimulator) {
  // GIVEN elastic cables over swivel pulleys, a density error and a load-cell bias
  sim::DatasetConfig config = noiseless_large();
  config.effects.axial_stiffness_n = 1.5e6;
  config.effects.pulley_radius_m = 0.15;
  config.effects.density_error = 0.05;
  config.effects.force_bias_n = 15.0;
  // WHEN fitted with those terms, THEN the readings and the truth come back exactly
  expect_exact_recovery(config, {Effect::kElasticity, Effect::kPulleyRadius, Effect::kDensityError, Effect::kLoadCell});
}

TEST(EffectModel, EncoderScaleComOffsetAndLoadCellGainReproduceTheSimulator) {
  sim::DatasetConfig config = noiseless_large();
  config.effects.encoder_scale = {0.003, -0.002, 0.001, 0.002};
  config.effects.com_offset_platform = Eigen::Vector3d(0.05, -0.03, 0.02);
  config.effects.force_gain = 0.02;
  expect_exact_recovery(config, {Effect::kEncoderScale, Effect::kComOffset, Effect::kLoadCell});
}

TEST(EffectModel, LoadCellBiasAloneReproducesTheSimulator) {
  // GIVEN a load cell reading 15 N high with its gain right, and elastic cables
  sim::DatasetConfig config = noiseless_large();
  config.effects.force_bias_n = 15.0;
  config.effects.axial_stiffness_n = 1.5e6;
  // WHEN fitted with the bias alone (no gain term), THEN the readings and the truth come back exactly
  expect_exact_recovery(config, {Effect::kElasticity, Effect::kLoadCellBias});
}

TEST(EffectModel, PoseReferenceOffsetReproducesTheSimulator) {
  // GIVEN a localization that reports the pose of a point 5 cm off the platform origin
  sim::DatasetConfig config = noiseless_large();
  config.effects.pose_reference_offset_platform = Eigen::Vector3d(0.03, 0.0, 0.04);
  // WHEN fitted with the pose reference offset, THEN the readings, the anchors and the offset come back exactly
  expect_exact_recovery(config, {Effect::kPoseReferenceOffset});
}

TEST(EffectModel, RefusesTwoFormsOfTheLoadCellTermInOneModel) {
  // GIVEN a model with both load_cell (bias and gain) and load_cell_bias, whose biases could not be told apart
  auto data = sim::simulate_dataset(noiseless_large());
  ASSERT_TRUE(data) << data.error();
  CalibrationOptions options;
  options.effects = {Effect::kLoadCellBias, Effect::kElasticity, Effect::kLoadCell};
  // WHEN calibrating, THEN it refuses, naming both terms
  const CalibrationResult result = calibrate(data->nominal, data->samples, options);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.message.find("load_cell_bias and load_cell share a parameter"), std::string::npos) << result.message;
}

}  // namespace
}  // namespace cdpr
