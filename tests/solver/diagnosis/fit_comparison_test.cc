// The likelihood-ratio test of two nested fits on all samples
// (solver/diagnosis/fit_comparison.h) on simulated data: it finds a hidden term, stays
// quiet on a term the data do not hold, grows stricter when the noise is
// larger than robot.toml says, and refuses fits it cannot compare; and
// Akaike's criterion between any two fits of the same samples.
#include "solver/diagnosis/fit_comparison.h"

#include <limits>

#include <gtest/gtest.h>

#include "diagnosis_configs.h"
#include "sim/dataset.h"

namespace cdpr {
namespace {

struct Fits {
  CalibrationResult base, with_term;
};

// The catenary fit and the fit with `term` on the same data; robot.toml's
// sensor sigmas are `stated` times the simulated ones.
Fits fit_both(const sim::DatasetConfig& config, Effect term, double stated = 1.0) {
  auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data) << (data ? "" : data.error());
  if (!data) return {};
  NoiseSigmas& noise = data->nominal.noise;
  noise.encoder_m *= stated;
  noise.force_n *= stated;
  noise.position_m *= stated;
  noise.orientation_rad *= stated;
  CalibrationOptions options;
  Fits fits;
  fits.base = calibrate(data->nominal, data->samples, options);
  options.effects = {term};
  fits.with_term = calibrate(data->nominal, data->samples, options);
  EXPECT_TRUE(fits.base.ok && fits.with_term.ok);
  return fits;
}

TEST(FitComparison, AHiddenElasticityIsFarBeyondChance) {
  // GIVEN cables with EA = 1.5e6 N
  sim::DatasetConfig config = test::large_robot_45_poses(2);
  config.effects.axial_stiffness_n = 1.5e6;
  // WHEN the catenary fit is compared with the fit with elasticity
  const Fits f = fit_both(config, Effect::kElasticity);
  const FitComparison c = compare_fits(f.base, f.with_term);
  // THEN the chi2 drop is twice the cost drop, one parameter was added, and p is tiny
  ASSERT_TRUE(c.comparable) << c.why_not;
  EXPECT_EQ(c.added_parameters, 1);
  EXPECT_DOUBLE_EQ(c.chi2_drop, 2.0 * (f.base.solver.final_cost - f.with_term.solver.final_cost));
  EXPECT_LT(c.p_value, 1e-4);
}

TEST(FitComparison, ATermTheDataDoNotHoldIsNotSignificant) {
  // GIVEN data without any effect, WHEN a 4-parameter term is added
  const Fits f = fit_both(test::large_robot_45_poses(3), Effect::kEncoderScale);
  const FitComparison c = compare_fits(f.base, f.with_term);
  // THEN it fits a little noise (chi2 drop of about its 4 parameters) and p is not small
  ASSERT_TRUE(c.comparable) << c.why_not;
  EXPECT_EQ(c.added_parameters, 4);
  EXPECT_GE(c.chi2_drop, 0.0);
  EXPECT_GT(c.p_value, 0.01);
  EXPECT_LT(c.scale, 1.2);
}

TEST(FitComparison, NoiseLargerThanRobotTomlSaysScalesTheDropDown) {
  // GIVEN sensor noise twice what robot.toml states, and no effect
  // WHEN a 4-parameter term is added
  const Fits f = fit_both(test::large_robot_45_poses(3), Effect::kEncoderScale, 0.5);
  const FitComparison c = compare_fits(f.base, f.with_term);
  // THEN the drop is judged against the measured misfit (chi2 / dof near 4),
  // not the stated sigma, and the term that only fits noise stays insignificant
  ASSERT_TRUE(c.comparable) << c.why_not;
  EXPECT_GT(c.scale, 3.0);
  EXPECT_LT(c.scale, 5.5);
  EXPECT_GT(c.p_value, 0.01);
}

TEST(FitComparison, RefusesFitsItCannotCompare) {
  const Fits f = fit_both(test::large_robot_45_poses(3), Effect::kElasticity);
  // GIVEN the larger model as the smaller one: it adds no parameter
  EXPECT_FALSE(compare_fits(f.with_term, f.base).comparable);
  // GIVEN fits that kept different samples
  CalibrationResult fewer = f.with_term;
  fewer.rejected_samples.push_back(7);
  const FitComparison c = compare_fits(f.base, fewer);
  EXPECT_FALSE(c.comparable);
  EXPECT_NE(c.why_not.find("different samples"), std::string::npos);
  // GIVEN a failed fit
  CalibrationResult failed;
  EXPECT_FALSE(compare_fits(f.base, failed).comparable);
}

TEST(AkaikeGain, RanksModelsByTheirDropLessTwoPerParameter) {
  // GIVEN the catenary fit and the fit with a 4-parameter term on data without it
  const Fits f = fit_both(test::large_robot_45_poses(3), Effect::kEncoderScale);
  // WHEN Akaike's criterion compares them either way
  const double drop = 2.0 * (f.base.solver.final_cost - f.with_term.solver.final_cost);
  // THEN it is the chi2 drop less 2 per parameter added, and its negative the other way round
  EXPECT_DOUBLE_EQ(akaike_gain(f.base, f.with_term), drop - 8.0);
  EXPECT_DOUBLE_EQ(akaike_gain(f.with_term, f.base), 8.0 - drop);
  // AND the term that fits only noise is not the better model
  EXPECT_LT(akaike_gain(f.base, f.with_term), 0.0);
}

TEST(AkaikeGain, AHiddenTermIsTheBetterModel) {
  // GIVEN cables with EA = 1.5e6 N, WHEN the catenary fit is compared with the fit with elasticity
  sim::DatasetConfig config = test::large_robot_45_poses(2);
  config.effects.axial_stiffness_n = 1.5e6;
  const Fits f = fit_both(config, Effect::kElasticity);
  // THEN the elasticity model gains
  EXPECT_GT(akaike_gain(f.base, f.with_term), 10.0);
}

TEST(AkaikeGain, FitsOfDifferentSamplesOrFailedFitsNeverGain) {
  const Fits f = fit_both(test::large_robot_45_poses(3), Effect::kElasticity);
  CalibrationResult fewer = f.with_term;
  fewer.rejected_samples.push_back(7);
  EXPECT_EQ(akaike_gain(f.base, fewer), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(akaike_gain(f.base, CalibrationResult{}), -std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace cdpr
