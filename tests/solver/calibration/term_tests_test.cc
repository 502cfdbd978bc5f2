// The score tests of the model terms a fit lacks (solver/calibration/term_tests.h):
// a term the data ask for is named although the chi-square test passes;
// effect-free data ask for none; a term in the model is not tested.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "solver/calibration/calibrate.h"

namespace cdpr {
namespace {

// The large robot, nominal anchors 10 m off; `density_error` hidden in the data.
sim::SimulatedDataset large_robot_data(int poses, std::uint64_t seed, double density_error = 0.0) {
  sim::DatasetConfig config;
  config.pose_count = poses;
  config.seed = seed;
  config.anchor_perturbation_m = 10.0;
  config.segments = 400;
  config.effects.density_error = density_error;
  auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data) << (data ? "" : data.error());
  return data ? std::move(*data) : sim::SimulatedDataset{};
}

const TermTest* test_of(const CalibrationResult& result, Effect e) {
  const auto at = std::find_if(result.term_tests.begin(), result.term_tests.end(),
                               [&](const TermTest& t) { return t.effect == e; });
  return at == result.term_tests.end() ? nullptr : &*at;
}

TEST(TermTests, ADensityErrorTheChiSquareTestMissesIsNamed) {
  // GIVEN 90 poses of cables 5 % heavier than robot.toml says: a misfit
  // whose chi2/dof stays inside the spread of effect-free data
  const sim::SimulatedDataset data = large_robot_data(90, 6, 0.05);
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  // THEN the chi-square test passes, but the fit is a misfit that names the density term with its evidence
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_GE(result.misfit_probability, CalibrationOptions{}.misfit_alpha);
  EXPECT_TRUE(result.misfit);
  const TermTest* density = test_of(result, Effect::kDensityError);
  ASSERT_NE(density, nullptr);
  EXPECT_TRUE(density->asked_for);
  EXPECT_EQ(density->dof, 1);
  EXPECT_GT(density->statistic, 40.0);
  EXPECT_LT(density->p, result.term_test_level);
  const std::string& warning = result.calibration.model_warning;
  EXPECT_NE(warning.find("the model lacks a term the data ask for: density_error ("), std::string::npos) << warning;
  EXPECT_NE(warning.find("cdpr-calib diagnose"), std::string::npos) << warning;
}

TEST(TermTests, EffectFreeDataAskForNoTerm) {
  // GIVEN effect-free data sets of 35 poses
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const sim::SimulatedDataset data = large_robot_data(35, seed);
    // WHEN calibrated with default options
    const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
    // THEN every known term is tested and none is asked for
    ASSERT_TRUE(result.ok) << result.message;
    EXPECT_EQ(result.term_tests.size(), static_cast<std::size_t>(kEffectCount)) << "seed " << seed;
    for (const TermTest& t : result.term_tests) {
      EXPECT_FALSE(t.asked_for) << effect_model_name(t.effect) << " seed " << seed << ": " << t.statistic;
    }
    EXPECT_FALSE(result.misfit) << result.calibration.model_warning;
    EXPECT_TRUE(result.calibration.model_warning.empty());
    EXPECT_DOUBLE_EQ(result.term_test_level, CalibrationOptions{}.term_test_alpha / kEffectCount);
  }
}

TEST(TermTests, ATermInTheModelIsNotTestedAndNoneIsAskedForOnceItIs) {
  // GIVEN the density-error data of the first test
  const sim::SimulatedDataset data = large_robot_data(90, 6, 0.05);
  // WHEN calibrated with the density term and a load-cell bias in the model
  CalibrationOptions options;
  options.effects = {Effect::kDensityError, Effect::kLoadCellBias};
  const CalibrationResult result = calibrate(data.nominal, data.samples, options);
  // THEN neither is tested, nor load_cell (which shares the bias), and the rest are not asked for
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_EQ(test_of(result, Effect::kDensityError), nullptr);
  EXPECT_EQ(test_of(result, Effect::kLoadCellBias), nullptr);
  EXPECT_EQ(test_of(result, Effect::kLoadCell), nullptr);
  EXPECT_EQ(result.term_tests.size(), static_cast<std::size_t>(kEffectCount - 3));
  for (const TermTest& t : result.term_tests) EXPECT_FALSE(t.asked_for) << effect_model_name(t.effect);
  EXPECT_FALSE(result.misfit) << result.calibration.model_warning;
}

TEST(TermTests, OffWithTheModelFitCheck) {
  // GIVEN the density-error data
  const sim::SimulatedDataset data = large_robot_data(90, 6, 0.05);
  // WHEN calibrated with the model-fit check off (as diagnose's own fits are)
  CalibrationOptions options;
  options.misfit_alpha = 0.0;
  const CalibrationResult result = calibrate(data.nominal, data.samples, options);
  // THEN no term is tested and nothing is flagged
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_TRUE(result.term_tests.empty());
  EXPECT_FALSE(result.misfit);
}

}  // namespace
}  // namespace cdpr
