// LevenbergMarquardt on small problems whose answers are known: curve fit,
// evaluability at the start and inside the search, robust loss.
#include <cmath>

#include <gtest/gtest.h>

#include "lm_test_factors.h"
#include "solver/nls/levenberg_marquardt.h"
#include "solver/nls/sized_factor.h"

namespace cdpr {
namespace {

using test::ExpCurveFactor;
using test::LineFactor;
using test::LogFactor;

const Key kCurve = EffectKey(0);

TEST(LevenbergMarquardt, FitsExponentialCurveToKnownParameters) {
  // GIVEN noise-free samples of y = exp(0.3 t + 0.1) and a start at (0, 0)
  const double m = 0.3, c = 0.1;
  Problem problem;
  problem.add_vector(kCurve, Eigen::Vector2d(0.0, 0.0));
  for (int k = 0; k < 40; ++k) {
    const double t = 0.125 * k;
    problem.add_factor(std::make_unique<ExpCurveFactor>(kCurve, t, std::exp(m * t + c)));
  }
  std::vector<IterationSummary> progress;
  SolverOptions options;
  options.progress = [&](const IterationSummary& s) { progress.push_back(s); };
  LevenbergMarquardt lm(problem, options);
  // WHEN solved
  const SolverSummary summary = lm.solve();
  // THEN it converges to (m, c) with a cost near zero, and progress saw every iteration
  EXPECT_EQ(summary.termination, TerminationType::kConverged) << summary.message;
  EXPECT_TRUE(summary.usable());
  EXPECT_NEAR(problem.vector(kCurve)(0), m, 1e-9);
  EXPECT_NEAR(problem.vector(kCurve)(1), c, 1e-9);
  EXPECT_GT(summary.initial_cost, 1.0);
  EXPECT_LT(summary.final_cost, 1e-15);
  EXPECT_GT(summary.successful_steps, 2);
  ASSERT_EQ(static_cast<int>(progress.size()), summary.iterations + 1);
  for (int i = 0; i <= summary.iterations; ++i) EXPECT_EQ(progress[i].iteration, i);
  EXPECT_DOUBLE_EQ(progress.front().cost, summary.initial_cost);
  EXPECT_DOUBLE_EQ(progress.back().cost, summary.final_cost);
  EXPECT_FALSE(summary.message.empty());
}

TEST(LevenbergMarquardt, StopsAtMaxIterationsWithTheBestPointSoFar) {
  // GIVEN the curve fit with a budget of 2 iterations
  Problem problem;
  problem.add_vector(kCurve, Eigen::Vector2d(0.0, 0.0));
  for (int k = 0; k < 40; ++k) {
    problem.add_factor(std::make_unique<ExpCurveFactor>(kCurve, 0.125 * k, std::exp(0.3 * 0.125 * k + 0.1)));
  }
  SolverOptions options;
  options.max_iterations = 2;
  const SolverSummary summary = LevenbergMarquardt(problem, options).solve();
  // THEN it says so, is still usable, and has not made things worse
  EXPECT_EQ(summary.termination, TerminationType::kMaxIterations);
  EXPECT_EQ(summary.iterations, 2);
  EXPECT_TRUE(summary.usable());
  EXPECT_LE(summary.final_cost, summary.initial_cost);
}

TEST(LevenbergMarquardt, ReportsTheFactorThatCannotBeEvaluatedAtTheStart) {
  // GIVEN a log factor at x = -1, where it refuses, as factor number 1
  int refusals = 0;
  Problem problem;
  problem.add_vector(EffectKey(0), Eigen::VectorXd::Constant(1, 1.0));
  problem.add_vector(EffectKey(1), Eigen::VectorXd::Constant(1, -1.0));
  problem.add_factor(std::make_unique<LogFactor>(EffectKey(0), 2.0, 1.0, &refusals));
  problem.add_factor(std::make_unique<LogFactor>(EffectKey(1), 2.0, 1.0, &refusals));
  // WHEN solved
  const SolverSummary summary = LevenbergMarquardt(problem, {}).solve();
  // THEN the termination names factor 1 and its variable, and nothing moved
  EXPECT_EQ(summary.termination, TerminationType::kNotEvaluable);
  EXPECT_FALSE(summary.usable());
  EXPECT_NE(summary.message.find("factor 1"), std::string::npos) << summary.message;
  EXPECT_NE(summary.message.find("effect[1]"), std::string::npos) << summary.message;
  EXPECT_EQ(problem.vector(EffectKey(1))(0), -1.0);
}

TEST(LevenbergMarquardt, RejectsStepsIntoTheNonEvaluableRegionAndStillConverges) {
  // GIVEN log(x) = log(0.001) from x = 10: the Gauss-Newton step goes to x < 0
  int refusals = 0;
  Problem problem;
  problem.add_vector(EffectKey(0), Eigen::VectorXd::Constant(1, 10.0));
  problem.add_factor(std::make_unique<LogFactor>(EffectKey(0), 0.001, 0.1, &refusals));
  SolverOptions options;
  options.initial_trust_radius = 1e16;  // make the first steps undamped
  int rejected = 0;
  options.progress = [&](const IterationSummary& s) { rejected += s.iteration > 0 && !s.step_accepted; };
  // WHEN solved
  const SolverSummary summary = LevenbergMarquardt(problem, options).solve();
  // THEN the refused candidates were rejected, the solver recovered and converged
  EXPECT_GT(refusals, 0);
  EXPECT_GE(rejected, refusals);
  EXPECT_EQ(summary.termination, TerminationType::kConverged) << summary.message;
  EXPECT_NEAR(problem.vector(EffectKey(0))(0), 0.001, 1e-9);
}

// r = 1 + 1e-12 x, its Jacobian given as 1: a cost flat to within the
// function tolerance where its linearisation promises a large gain, as at
// a minimum whose rounding decides the gain ratio.
class FlatFactor final : public SizedFactor<1, 1> {
 public:
  explicit FlatFactor(Key key) : SizedFactor({key}, Loss{}) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    r[0] = 1.0 + 1e-12 * x[0][0];
    if (auto J = jacobian<0>(j)) (*J)(0, 0) = 1.0;
    return true;
  }
};

TEST(LevenbergMarquardt, ARefusedStepThatChangesTheCostWithinTheToleranceEndsTheSolve) {
  // GIVEN a cost that the first step changes by 1e-12 relative, far less
  // than its linearisation predicts
  Problem problem;
  problem.add_vector(EffectKey(0), Eigen::VectorXd::Zero(1));
  problem.add_factor(std::make_unique<FlatFactor>(EffectKey(0)));
  // WHEN solved
  const SolverSummary summary = LevenbergMarquardt(problem, {}).solve();
  // THEN that refused step ends it, converged on the function tolerance,
  // where the trust region would otherwise shrink for 13 more iterations
  EXPECT_EQ(summary.termination, TerminationType::kConverged) << summary.message;
  EXPECT_EQ(summary.iterations, 1);
  EXPECT_EQ(summary.successful_steps, 0);
  EXPECT_NE(summary.message.find("function tolerance"), std::string::npos) << summary.message;
  EXPECT_EQ(problem.vector(EffectKey(0))(0), 0.0);
}

// Line y = 2 t - 1 sampled with small alternating noise and one gross outlier.
double fit_line_slope(double huber_width) {
  Problem problem;
  problem.add_vector(kCurve, Eigen::Vector2d(0.0, 0.0));
  for (int k = 0; k < 21; ++k) {
    const double t = 0.5 * k;
    double y = 2.0 * t - 1.0 + (k % 2 ? 0.01 : -0.01);
    if (k == 20) y += 50.0;  // the outlier, at the end where it has most leverage
    problem.add_factor(std::make_unique<LineFactor>(kCurve, t, y, 0.01, Loss{huber_width}));
  }
  const SolverSummary summary = LevenbergMarquardt(problem, {}).solve();
  EXPECT_TRUE(summary.usable()) << summary.message;
  return problem.vector(kCurve)(0);
}

TEST(LevenbergMarquardt, HuberLossDownweightsAnOutlier) {
  // GIVEN the same data fitted with plain least squares and with Huber (1.5 sigma)
  const double plain = fit_line_slope(0.0);
  const double robust = fit_line_slope(1.5);
  // THEN least squares is dragged by the outlier, Huber stays near the true slope
  EXPECT_GT(std::abs(plain - 2.0), 0.5);
  EXPECT_LT(std::abs(robust - 2.0), 0.01);
}

}  // namespace
}  // namespace cdpr
