#include "src/calibration/fit_validation.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "../../solver/model/test_robots.h"

namespace cdpr::calibration {
namespace {

// A converged fit whose residuals and sigmas are at the robot's noise level.
CalibrationResult good_result(const Robot& robot) {
  CalibrationResult result;
  result.ok = true;
  result.solver.termination = TerminationType::kConverged;
  result.calibration.samples = 35;
  for (const Winch& winch : robot.winches) {
    WinchCalibration& w = result.calibration.winches.emplace_back();
    w.anchor_world = winch.anchor_world + Eigen::Vector3d(0.05, -0.03, 0.02);
    w.anchor_sigma = Eigen::Vector3d(0.01, 0.01, 0.02);
    w.offset_m = 2.0;
    w.offset_sigma_m = 0.01;
  }
  result.calibration.fit.rms_encoder_m = robot.noise.encoder_m;
  result.calibration.fit.rms_force_n = robot.noise.force_n;
  return result;
}

bool has_reason(const ValidationResult& validation, const std::string& words) {
  return validation.summary().find(words) != std::string::npos;
}

TEST(FitValidation, AFitAtTheNoiseLevelIsAccepted) {
  // GIVEN a converged fit with residuals at one sigma
  const Robot robot = cdpr::test::large_robot();
  // WHEN validated without a previous calibration
  const ValidationResult validation = validate_fit(good_result(robot), robot, nullptr, {});
  // THEN it is accepted
  EXPECT_TRUE(validation.accepted()) << validation.summary();
}

TEST(FitValidation, AFailedOrUnconvergedSolveIsRefused) {
  const Robot robot = cdpr::test::large_robot();
  // GIVEN a failed solve and one that ran out of iterations
  CalibrationResult failed = good_result(robot);
  failed.ok = false;
  failed.message = "not evaluable at the start";
  CalibrationResult stopped = good_result(robot);
  stopped.solver.termination = TerminationType::kMaxIterations;
  stopped.solver.message = "200 iterations";
  // WHEN validated THEN each is refused with the solver's message
  EXPECT_TRUE(has_reason(validate_fit(failed, robot, nullptr, {}), "solve failed: not evaluable"));
  EXPECT_TRUE(has_reason(validate_fit(stopped, robot, nullptr, {}), "did not converge: 200 iterations"));
  // AND running out of iterations is accepted when allowed
  ValidationLimits lenient;
  lenient.accept_max_iterations = true;
  EXPECT_TRUE(validate_fit(stopped, robot, nullptr, lenient).accepted());
}

TEST(FitValidation, ResidualsAboveThreeSigmaAreRefused) {
  // GIVEN encoder residuals at 3.5 sigma and force residuals at 4 sigma
  const Robot robot = cdpr::test::large_robot();
  CalibrationResult result = good_result(robot);
  result.calibration.fit.rms_encoder_m = 3.5 * robot.noise.encoder_m;
  result.calibration.fit.rms_force_n = 4.0 * robot.noise.force_n;
  // WHEN validated
  const ValidationResult validation = validate_fit(result, robot, nullptr, {});
  // THEN both are named
  EXPECT_EQ(validation.reasons.size(), 2u) << validation.summary();
  EXPECT_TRUE(has_reason(validation, "encoder residual rms 0.035 m exceeds 3 sigma"));
  EXPECT_TRUE(has_reason(validation, "force residual rms 20 N exceeds 3 sigma"));
}

TEST(FitValidation, LargeSigmasAndNonFiniteValuesAreRefusedPerCable) {
  // GIVEN cable 1 poorly observed and cable 3 with a NaN offset
  const Robot robot = cdpr::test::large_robot();
  CalibrationResult result = good_result(robot);
  result.calibration.winches[1].anchor_sigma.z() = 0.2;
  result.calibration.winches[1].offset_sigma_m = 0.3;
  result.calibration.winches[3].offset_m = std::numeric_limits<double>::quiet_NaN();
  // WHEN validated
  const ValidationResult validation = validate_fit(result, robot, nullptr, {});
  // THEN each problem names its cable
  EXPECT_TRUE(has_reason(validation, "cable 1: anchor sigma 0.2 m above 0.05 m"));
  EXPECT_TRUE(has_reason(validation, "cable 1: offset sigma 0.3 m"));
  EXPECT_TRUE(has_reason(validation, "cable 3: non-finite"));
}

TEST(FitValidation, AnAnchorJumpFromThePreviousCalibrationIsRefused) {
  // GIVEN a previous calibration and a new fit that moves anchor 2 by 0.8 m
  const Robot robot = cdpr::test::large_robot();
  const CalibrationResult previous = good_result(robot);
  CalibrationResult result = good_result(robot);
  result.calibration.winches[2].anchor_world.x() += 0.8;
  // WHEN validated against the previous one
  const ValidationResult validation = validate_fit(result, robot, &previous.calibration, {});
  // THEN only cable 2 is refused, with the distance
  ASSERT_EQ(validation.reasons.size(), 1u) << validation.summary();
  EXPECT_TRUE(has_reason(validation, "cable 2: anchor moved 0.8 m since the previous calibration"));
}

TEST(FitValidation, TooFewSamplesOrAWrongCableCountIsRefused) {
  const Robot robot = cdpr::test::large_robot();
  // GIVEN a fit from 6 samples and one with 3 cables
  CalibrationResult few = good_result(robot);
  few.calibration.samples = 6;
  CalibrationResult short_result = good_result(robot);
  short_result.calibration.winches.pop_back();
  // WHEN validated THEN both are refused with the counts
  EXPECT_TRUE(has_reason(validate_fit(few, robot, nullptr, {}), "only 6 samples (at least 10 needed)"));
  EXPECT_TRUE(has_reason(validate_fit(short_result, robot, nullptr, {}), "calibration has 3 cables, robot has 4"));
}

}  // namespace
}  // namespace cdpr::calibration
