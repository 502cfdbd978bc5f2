// The model-fit test's verdict on a final fit (solver/calibration/model_fit_check.h).
#include <cmath>

#include <gtest/gtest.h>

#include "solver/calibration/model_fit_check.h"

namespace cdpr {
namespace {

// A fit of 4 cables (16 global unknowns) with `dof` redundant rows and
// every sigma 0.01 m.
CalibrationResult fit_with(double chi_square, int dof, TerminationType termination) {
  CalibrationResult r;
  r.ok = true;
  r.chi_square = chi_square;
  r.degrees_of_freedom = dof;
  r.solver.termination = termination;
  r.solver.iterations = 1000;
  r.global_covariance = Eigen::MatrixXd::Identity(16, 16) * 1e-4;
  r.calibration.winches.resize(kCableCount);
  for (WinchCalibration& w : r.calibration.winches) {
    w.anchor_sigma = Eigen::Vector3d::Constant(0.01);
    w.offset_sigma_m = 0.01;
  }
  return r;
}

TEST(ModelFitCheck, AFitThatStoppedAtTheIterationLimitIsNotAGoodCalibration) {
  // GIVEN a fit whose chi-square passes but whose solver ran out of iterations
  CalibrationResult r = fit_with(222.0, 222, TerminationType::kMaxIterations);
  // WHEN tested
  assess_model_fit(r, CalibrationOptions{});
  // THEN it is flagged (cdpr-calib solve exits 3, the daemon refuses it) as not converged
  EXPECT_TRUE(r.misfit);
  EXPECT_NE(r.calibration.model_warning.find("not converged"), std::string::npos) << r.calibration.model_warning;
  // AND the advice is a better start, not a hunt for a model term
  EXPECT_EQ(r.misfit_cause, MisfitCause::kNotConverged);
  EXPECT_EQ(std::string(misfit_advice(r.misfit_cause)).find("diagnose"), std::string::npos);
  // AND its sigmas are not scaled: the chi-square does not ask for it
  EXPECT_DOUBLE_EQ(r.calibration.winches[0].offset_sigma_m, 0.01);
}

TEST(ModelFitCheck, ResidualsNoModelTermLeavesAreAFitThatDidNotReachTheReadings) {
  // GIVEN a converged fit with chi2 / dof 7.6e8 (rms encoder residual 37 m
  // on rows of 1.1 mm noise: a fit 34 m off the true anchors)
  CalibrationResult r = fit_with(1.69e11, 222, TerminationType::kConverged);
  assess_model_fit(r, CalibrationOptions{});
  // THEN it is flagged with words that do not send the user after a missing model term
  EXPECT_TRUE(r.misfit);
  EXPECT_NE(r.calibration.model_warning.find("did not reach the readings"), std::string::npos);
  EXPECT_EQ(r.calibration.model_warning.find("run cdpr-calib diagnose"), std::string::npos);
  EXPECT_EQ(r.misfit_cause, MisfitCause::kUnreached);
  EXPECT_EQ(std::string(misfit_advice(r.misfit_cause)).find("diagnose"), std::string::npos);
}

TEST(ModelFitCheck, TooFewRedundantRowsAskForPosesNotForAModelTerm) {
  // GIVEN a fit with fewer redundant rows than its 16 global unknowns
  CalibrationResult r = fit_with(5.0, 8, TerminationType::kConverged);
  assess_model_fit(r, CalibrationOptions{});
  // THEN it is flagged as under-determined and the advice is more poses
  EXPECT_TRUE(r.misfit);
  EXPECT_EQ(r.misfit_cause, MisfitCause::kUnderDetermined);
  EXPECT_NE(std::string(misfit_advice(r.misfit_cause)).find("poses"), std::string::npos);
}

TEST(ModelFitCheck, AModestMisfitPointsToAHiddenEffect) {
  // GIVEN a converged fit with chi2 / dof 1.5 on 222 degrees of freedom
  CalibrationResult r = fit_with(333.0, 222, TerminationType::kConverged);
  assess_model_fit(r, CalibrationOptions{});
  // THEN the sigmas are scaled by sqrt(1.5) and the user is sent to diagnose
  EXPECT_TRUE(r.misfit);
  EXPECT_NEAR(r.calibration.winches[0].offset_sigma_m, 0.01 * std::sqrt(1.5), 1e-12);
  EXPECT_NE(r.calibration.model_warning.find("run cdpr-calib diagnose"), std::string::npos);
  EXPECT_EQ(r.misfit_cause, MisfitCause::kModel);
  EXPECT_NE(std::string(misfit_advice(r.misfit_cause)).find("diagnose"), std::string::npos);
}

TEST(ModelFitCheck, AConvergedFitThatFitsPasses) {
  CalibrationResult r = fit_with(210.0, 222, TerminationType::kConverged);
  assess_model_fit(r, CalibrationOptions{});
  EXPECT_FALSE(r.misfit);
  EXPECT_TRUE(r.calibration.model_warning.empty());
  EXPECT_EQ(r.misfit_cause, MisfitCause::kNone);
}

}  // namespace
}  // namespace cdpr
