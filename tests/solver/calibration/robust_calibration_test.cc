// The robust calibration on simulated data: gross errors found, named and
// left out; clean data fitted exactly as by least squares; too many gross
// errors refused; a model that does not fit, or too few poses, said so.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "solver/calibration/calibrate.h"

namespace cdpr {
namespace {

sim::SimulatedDataset simulate(sim::DatasetConfig config) {
  config.segments = 400;
  auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data) << (data ? "" : data.error());
  return data ? std::move(*data) : sim::SimulatedDataset{};
}

sim::DatasetConfig large(int poses, std::uint64_t seed) {
  sim::DatasetConfig c;
  c.pose_count = poses;
  c.seed = seed;
  c.anchor_perturbation_m = 10.0;
  return c;
}

sim::DatasetConfig small(int poses, std::uint64_t seed) {
  sim::DatasetConfig c;
  c.preset = sim::Preset::kSmall;
  c.pose_count = poses;
  c.seed = seed;
  c.anchor_perturbation_m = 1.0;
  return c;
}

// 5 % rows with a 0.5-2 m encoder error and 5 % with a load-cell spike.
sim::DatasetConfig with_gross_errors(sim::DatasetConfig config) {
  config.gross_errors.encoder_fraction = 0.05;
  config.gross_errors.force_fraction = 0.05;
  return config;
}

double mean_anchor_error(const Calibration& cal, const Truth& truth) {
  double sum = 0.0;
  for (int i = 0; i < kCableCount; ++i) sum += (cal.winches[i].anchor_world - truth.winches[i].anchor_world).norm();
  return sum / kCableCount;
}

TEST(RobustCalibration, PlantedGrossErrorsAreRejectedAndNamed) {
  // GIVEN 35 poses, nominal anchors 10 m off, 10 % rows with a 0.5-2 m
  // encoder error and 5 % with a load-cell spike
  sim::DatasetConfig config = large(35, 3);
  config.gross_errors.encoder_fraction = 0.1;
  config.gross_errors.force_fraction = 0.05;
  const sim::SimulatedDataset data = simulate(config);
  ASSERT_EQ(data.truth.outliers.size(), 6u);
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  // THEN it succeeds without those readings, every planted reading named (row,
  // sensor, cable) at many sigmas, and the anchors as good as on clean data
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_EQ(result.calibration.samples, 35);  // only the readings are left out
  for (const SensorReading& planted : data.truth.outliers) {
    const auto hit = std::find_if(result.calibration.rejected.begin(), result.calibration.rejected.end(),
                                  [&](const SensorReading& r) {
                                    return r.row == planted.row && r.sensor == planted.sensor && r.cable == planted.cable;
                                  });
    ASSERT_NE(hit, result.calibration.rejected.end()) << "row " << planted.row;
    EXPECT_GT(std::abs(hit->value), 20.0);
  }
  EXPECT_LT(mean_anchor_error(result.calibration, data.truth), 0.6);
  EXPECT_FALSE(result.misfit) << result.calibration.model_warning;
}

TEST(RobustCalibration, TheSummaryCountsTheStepsOfEveryStage) {
  // GIVEN clean data, fitted in the robust stage and then the final one
  const sim::SimulatedDataset data = simulate(large(35, 5));
  CalibrationOptions options;
  int iterations = 0;
  int accepted = 0;
  options.progress = [&](const IterationSummary& s) {
    iterations += s.iteration > 0;
    accepted += s.iteration > 0 && s.step_accepted;
  };
  // WHEN calibrated
  const CalibrationResult result = calibrate(data.nominal, data.samples, options);
  // THEN the summary's iterations and accepted steps are those of every
  // stage together, as the progress lines showed them
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_GT(accepted, 0);
  EXPECT_EQ(result.solver.iterations, iterations);
  EXPECT_EQ(result.solver.successful_steps, accepted);
}

TEST(RobustCalibration, CleanDataGivesTheLeastSquaresFitAndItsSigmas) {
  // GIVEN effect-free data without gross errors
  const sim::SimulatedDataset data = simulate(large(35, 5));
  // WHEN fitted robustly (default) and by least squares alone
  const CalibrationResult robust = calibrate(data.nominal, data.samples, CalibrationOptions{});
  CalibrationOptions plain_options;
  plain_options.robust = false;
  const CalibrationResult plain = calibrate(data.nominal, data.samples, plain_options);
  // THEN nothing is rejected and both reach the same minimum with the same sigmas
  ASSERT_TRUE(robust.ok) << robust.message;
  ASSERT_TRUE(plain.ok) << plain.message;
  EXPECT_TRUE(robust.calibration.rejected.empty());
  EXPECT_NEAR(robust.solver.final_cost, plain.solver.final_cost, 1e-6 * plain.solver.final_cost);
  for (int i = 0; i < kCableCount; ++i) {
    const WinchCalibration &r = robust.calibration.winches[i], &p = plain.calibration.winches[i];
    EXPECT_LT((r.anchor_world - p.anchor_world).norm(), 1e-4);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(r.anchor_sigma(a), p.anchor_sigma(a), 1e-3 * p.anchor_sigma(a));
  }
  EXPECT_FALSE(robust.misfit) << robust.calibration.model_warning;
}

TEST(RobustCalibration, ARobustFitConvergedInsideTheWidthIsTheFinalFit) {
  // GIVEN clean data, whose robust fit ends with every reading inside the
  // Huber width, and the solves' starts counted (progress line 0)
  const sim::SimulatedDataset data = simulate(large(35, 5));
  auto solves = [&](CalibrationOptions options) {
    int starts = 0;
    options.progress = [&](const IterationSummary& s) { starts += s.iteration == 0; };
    const CalibrationResult result = calibrate(data.nominal, data.samples, options);
    EXPECT_TRUE(result.ok) << result.message;
    return starts;
  };
  // WHEN calibrated with least squares as the final loss, and with a final
  // Huber loss of 1 sigma, which clean readings exceed
  CalibrationOptions narrow;
  narrow.huber_width = 1.0;
  // THEN the first takes the robust fit's minimum without a final solve,
  // the second solves again
  EXPECT_EQ(solves(CalibrationOptions{}), 1);
  EXPECT_EQ(solves(narrow), 2);
}

TEST(RobustCalibration, TooManyGrossErrorsAreRefusedWithTheReason) {
  // GIVEN 20 % rows with gross encoder errors, and at most 10 % allowed
  sim::DatasetConfig config = large(35, 3);
  config.gross_errors.encoder_fraction = 0.2;
  const sim::SimulatedDataset data = simulate(config);
  CalibrationOptions options;
  options.max_rejected_fraction = 0.1;
  // WHEN calibrated
  const CalibrationResult result = calibrate(data.nominal, data.samples, options);
  // THEN it is refused, naming the fraction, the rows and what to do
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.message.find("need attention"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("more than the 10 % allowed"), std::string::npos) << result.message;
  EXPECT_FALSE(result.gross_errors.empty());
}

// Every planted reading named, and no reading of a clean row left out.
void expect_exactly_the_planted_rows(const CalibrationResult& result, const sim::SimulatedDataset& data) {
  for (const SensorReading& planted : data.truth.outliers) {
    EXPECT_TRUE(std::any_of(result.calibration.rejected.begin(), result.calibration.rejected.end(),
                            [&](const SensorReading& r) {
                              return r.row == planted.row && r.sensor == planted.sensor && r.cable == planted.cable;
                            }))
        << "row " << planted.row;
  }
  for (const SensorReading& r : result.calibration.rejected) {
    EXPECT_TRUE(std::isfinite(r.value));
    EXPECT_TRUE(std::any_of(data.truth.outliers.begin(), data.truth.outliers.end(),
                            [&](const SensorReading& planted) { return planted.row == r.row; }))
        << "clean row " << r.row << " left out";
  }
}

TEST(RobustCalibration, OneGrossErrorThatCapturesTheRobustFitOnNinePosesIsStillFound) {
  // GIVEN 9 poses, nominal anchors 10 m off, one row with a 1.7 m encoder
  // error whose leverage pulls the robust fit where most rows look bad
  const sim::SimulatedDataset data = simulate(with_gross_errors(large(9, 18)));
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  // THEN the leave-one-row-out hypotheses find the bad row: the fit is kept,
  // every planted reading named and only readings of planted rows left out
  ASSERT_TRUE(result.ok) << result.message;
  expect_exactly_the_planted_rows(result, data);
  EXPECT_LT(mean_anchor_error(result.calibration, data.truth), 2.0);
}

TEST(RobustCalibration, AStartThatCannotTakeEveryRowStillReachesTheTruthStartedMinimum) {
  // GIVEN 9 clean poses of the large robot with nominal anchors 20 m off,
  // from which 3 rows cannot be started (their cable geometry is infeasible)
  sim::DatasetConfig config = large(9, 22);
  config.anchor_perturbation_m = 20.0;
  const auto simulated = sim::simulate_dataset(config);
  ASSERT_TRUE(simulated) << simulated.error();
  const sim::SimulatedDataset& data = *simulated;
  Robot at_truth = data.nominal;
  for (int i = 0; i < kCableCount; ++i) at_truth.winches[i].anchor_world = data.truth.winches[i].anchor_world;
  // WHEN calibrated from the nominal anchors and from the true ones
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  const CalibrationResult reference = calibrate(at_truth, data.samples, CalibrationOptions{});
  // THEN the multi-start fits every row and ends at the same minimum
  ASSERT_TRUE(result.ok) << result.message;
  ASSERT_TRUE(reference.ok) << reference.message;
  EXPECT_EQ(result.calibration.samples, 9);
  EXPECT_TRUE(result.rejected_samples.empty());
  EXPECT_NEAR(result.solver.final_cost, reference.solver.final_cost, 1e-6 * reference.solver.final_cost);
}

// 5 % rows with an encoder error and 5 % with a load-cell spike planted on
// `config`, calibrated with default options: exactly the planted readings
// named, no misfit, the anchors within max_error_m.
void expect_planted_named_without_misfit(const sim::DatasetConfig& config, double max_error_m) {
  const auto simulated = sim::simulate_dataset(with_gross_errors(config));
  ASSERT_TRUE(simulated) << simulated.error();
  const CalibrationResult result = calibrate(simulated->nominal, simulated->samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  expect_exactly_the_planted_rows(result, *simulated);
  EXPECT_FALSE(result.misfit) << result.calibration.model_warning;
  EXPECT_LT(mean_anchor_error(result.calibration, simulated->truth), max_error_m);
}

TEST(RobustCalibration, AGrossErrorThatMakesGoodRowsLookBadUntilTheRunIsRefusedIsStillNamed) {
  // GIVEN 9 poses, nominal anchors 10 m off, +1.36 m on encoder 0 of row 2,
  // -221 N on the load cell of row 3 and +1.29 m on encoder 2 of row 6,
  // which cable 2's anchor and offset absorb: encoder 2 of rows 7 and 8 then
  // looks 17-20 sigma off, and with them 4 of 9 rows are flagged, more than
  // the 40 % allowed, after the leave-one-row-out hypotheses too
  sim::DatasetConfig config = large(9, 21);
  config.gross_errors.encoder_fraction = 0.2;
  config.gross_errors.force_fraction = 0.05;
  const auto simulated = sim::simulate_dataset(config);
  ASSERT_TRUE(simulated) << simulated.error();
  ASSERT_EQ(simulated->truth.outliers.size(), 3u);
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(simulated->nominal, simulated->samples, CalibrationOptions{});
  // THEN the swap test of the refused set trades the good readings for the
  // absorbed one: the fit is kept, exactly the planted readings are named
  // (each with its residual), and it passes the model-fit test
  ASSERT_TRUE(result.ok) << result.message;
  expect_exactly_the_planted_rows(result, *simulated);
  EXPECT_EQ(result.calibration.rejected.size(), 3u);
  for (const SensorReading& r : result.gross_errors) EXPECT_TRUE(std::isfinite(r.value)) << "row " << r.row;
  EXPECT_FALSE(result.misfit) << result.calibration.model_warning;
  EXPECT_LT(mean_anchor_error(result.calibration, simulated->truth), 2.5);
}

TEST(RobustCalibration, AGrossErrorAbsorbedByItsRowsLoadCellIsStillNamed) {
  // GIVEN 9 poses, nominal anchors 10 m off, a 0.51 m encoder error that
  // the robust fit's leave-one-out puts on its row's load cell (whose
  // absence lets the row's force absorb it), and a load-cell spike
  // WHEN calibrated with default options
  // THEN the swap test moves the rejection to the encoder: both planted
  // readings named, nothing else left out, no misfit
  expect_planted_named_without_misfit(large(9, 50), 2.0);
}

TEST(RobustCalibration, AGrossErrorAbsorbedByItsCableIsStillNamed) {
  // GIVEN 8 poses of the small robot, nominal anchors 1 m off, a 1.49 m
  // encoder error that cable 0's anchor and offset absorb, so that cable
  // 0's readings of two other rows look bad, and a load-cell spike
  const sim::DatasetConfig config = small(8, 33);
  // WHEN calibrated with default options
  // THEN the swap test trades the good readings for the bad one
  expect_planted_named_without_misfit(config, 1.0);
}

TEST(RobustCalibration, ALoadCellSpikeItsRowsPoseAbsorbsIsStillNamed) {
  // GIVEN 35 poses, nominal anchors 10 m off, where row 12's load cell is
  // off by -86 N (17 sigma) and the row's orientation takes most of it: its
  // residual stays near 2 sigma, so the robust fit never flags the row,
  // while leaving it out lowers the chi-square by 38 (6.2 sigma)
  const sim::DatasetConfig config = large(35, 39);
  // WHEN calibrated with default options
  // THEN the studentised test of the kept readings leaves it out: every
  // planted reading named, nothing else left out, no misfit
  expect_planted_named_without_misfit(config, 1.0);
}

TEST(RobustCalibration, ARowWithAnEncoderErrorAndALoadCellSpikeLosesBoth) {
  // GIVEN 45 poses of the small robot over its footprint, nominal anchors
  // 0.5 m off, where row 35 holds a 0.83 m encoder error on cable 2 and a
  // -198 N load-cell spike: without the load cell, the row's pose takes the
  // encoder error into its prior and every reading of the row looks clean
  sim::DatasetConfig config = small(45, 23);
  config.anchor_perturbation_m = 0.5;
  config.workspace_min = Eigen::Vector3d(1.5, 0.7, 3.0);
  config.workspace_max = Eigen::Vector3d(11.0, 3.8, 22.0);
  // WHEN calibrated with default options
  // THEN the row's chi-square still stands out, so both readings are left out
  expect_planted_named_without_misfit(config, 0.2);
}

TEST(RobustCalibration, AReadingTheDataCannotTellFromAnotherIsNamedWithItAsASuspectGroup) {
  // GIVEN 35 poses of the large robot, nominal anchors 10 m off, where row 6
  // holds a -0.67 m error on encoder 0 and a +116 N load-cell spike: with
  // encoder 0 left out, leaving out encoder 3 explains the rest of the row
  // about as well as leaving out the load cell (chi-square 2.7 against 4.4)
  const sim::SimulatedDataset data = simulate(with_gross_errors(large(35, 48)));
  const auto spike = std::find_if(data.truth.outliers.begin(), data.truth.outliers.end(),
                                  [](const SensorReading& p) { return p.row == 6 && p.sensor == SensorKind::kForce; });
  ASSERT_NE(spike, data.truth.outliers.end());
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  // THEN the planted spike is named, in a suspect group with every reading
  // of its row the data cannot tell from it, all of them left out
  const std::vector<SensorReading>& rejected = result.calibration.rejected;
  const auto named = std::find_if(rejected.begin(), rejected.end(), [](const SensorReading& r) {
    return r.row == 6 && r.sensor == SensorKind::kForce;
  });
  ASSERT_NE(named, rejected.end());
  EXPECT_NE(named->group, 0);
  const auto members = std::count_if(rejected.begin(), rejected.end(), [&](const SensorReading& r) {
    return r.row == 6 && r.group == named->group;
  });
  EXPECT_GE(members, 2);
  EXPECT_FALSE(result.misfit) << result.calibration.model_warning;
}

TEST(RobustCalibration, AFitThatKeptAGrossErrorAndMisfitsIsRedoneFromTheBadRowLeftOut) {
  // GIVEN 8 poses of the small robot, nominal anchors 1 m off, a 1.75 m
  // encoder error and a load-cell spike, where the robust fit flags good
  // readings, keeps the bad one and its refit misfits
  const sim::SimulatedDataset data = simulate(with_gross_errors(small(8, 45)));
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  // THEN the leave-one-row-out hypotheses find the fit that leaves out every
  // planted reading and fits the rest
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_FALSE(result.misfit) << result.calibration.model_warning;
  for (const SensorReading& planted : data.truth.outliers) {
    EXPECT_TRUE(std::any_of(result.calibration.rejected.begin(), result.calibration.rejected.end(),
                            [&](const SensorReading& r) {
                              return r.row == planted.row && r.sensor == planted.sensor && r.cable == planted.cable;
                            }))
        << "row " << planted.row;
  }
  EXPECT_LT(mean_anchor_error(result.calibration, data.truth), 2.0);
}

TEST(RobustCalibration, ACentreOfMassErrorIsFlaggedAndItsSigmasScaledUp) {
  // GIVEN data whose platform centre of mass is 1 m off the nominal one
  sim::DatasetConfig config = large(90, 1);
  config.effects.com_offset_platform = Eigen::Vector3d(0.0, 0.0, 1.0);
  const sim::SimulatedDataset data = simulate(config);
  CalibrationOptions options;
  const CalibrationResult result = calibrate(data.nominal, data.samples, options);
  // THEN the fit says the model does not fit, with the evidence and where to go
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_TRUE(result.misfit);
  EXPECT_NE(result.calibration.model_warning.find("chi-square"), std::string::npos);
  EXPECT_NE(result.calibration.model_warning.find("cdpr-calib diagnose"), std::string::npos);
  // AND the sigmas are those of the covariance times sqrt(chi2 / dof)
  options.misfit_alpha = 0.0;  // the test off: unscaled sigmas
  const CalibrationResult unscaled = calibrate(data.nominal, data.samples, options);
  ASSERT_TRUE(unscaled.ok);
  EXPECT_FALSE(unscaled.misfit);
  const double scale = std::sqrt(result.chi_square / result.degrees_of_freedom);
  EXPECT_GT(scale, 1.0);
  EXPECT_NEAR(result.calibration.winches[0].anchor_sigma.x(), scale * unscaled.calibration.winches[0].anchor_sigma.x(),
              1e-9);
}

TEST(RobustCalibration, ThreePosesAreUnderDetermined) {
  const sim::SimulatedDataset data = simulate(large(3, 2));
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  EXPECT_TRUE(result.misfit);
  EXPECT_NE(result.calibration.model_warning.find("under-determined"), std::string::npos)
      << result.calibration.model_warning;
}

}  // namespace
}  // namespace cdpr
