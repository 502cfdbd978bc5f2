// The small dense damped solver: convergence, its stops and why it says it
// stopped, bounds, central differences and a manifold.
#include "solver/nls/dense_damped_solver.h"

#include <cmath>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

namespace cdpr {
namespace {

using Solver2 = DenseDampedSolver<2, 2>;

// Rosenbrock as least squares: r = (10 (y - x^2), 1 - x), minimum 0 at (1, 1).
bool rosenbrock_dense(const Eigen::Vector2d& x, Eigen::Vector2d& r, Eigen::Matrix2d* jacobian) {
  r << 10.0 * (x(1) - x(0) * x(0)), 1.0 - x(0);
  if (jacobian) *jacobian << -20.0 * x(0), 10.0, -1.0, 0.0;
  return true;
}

DenseDampedOptions tight_dense() {
  DenseDampedOptions o;
  o.gain_tolerance = 1e-14;
  o.gain_floor = 1e-20;
  return o;
}

TEST(DenseDampedSolver, ReachesTheMinimumOfRosenbrockFromTheClassicStart) {
  // GIVEN Rosenbrock's valley from (-1.2, 1)
  Solver2 solver(tight_dense());
  Eigen::Vector2d x(-1.2, 1.0);
  // WHEN minimised with the analytic Jacobian
  const DenseDampedSummary summary = solver.minimize(x, rosenbrock_dense);
  // THEN it ends at (1, 1), having said it converged
  EXPECT_TRUE(summary.converged()) << summary.message();
  EXPECT_NEAR(x(0), 1.0, 1e-6);
  EXPECT_NEAR(x(1), 1.0, 1e-6);
  EXPECT_DOUBLE_EQ(summary.initial_chi2, 100.0 * 0.44 * 0.44 + 2.2 * 2.2);
  EXPECT_LT(summary.final_chi2, 1e-12);
  EXPECT_GT(summary.accepted, 0);
  EXPECT_LE(summary.accepted, summary.trials);
}

TEST(DenseDampedSolver, CentralDifferencesFindTheSameMinimum) {
  Solver2 solver(tight_dense());
  Eigen::Vector2d x(-1.2, 1.0);
  const DenseDampedSummary summary =
      solver.minimize_numeric(x, [](const Eigen::Vector2d& at, Eigen::Vector2d& r) { return rosenbrock_dense(at, r, nullptr); });
  EXPECT_TRUE(summary.converged()) << summary.message();
  EXPECT_NEAR(x(0), 1.0, 1e-6);
  EXPECT_NEAR(x(1), 1.0, 1e-6);
}

TEST(DenseDampedSolver, ASquareSystemStopsAtItsRootByTheResidualTolerance) {
  // GIVEN r = (x^2 - 2, y - x): the root (sqrt 2, sqrt 2)
  DenseDampedOptions o;
  o.residual_tolerance = 1e-12;
  Solver2 solver(o);
  Eigen::Vector2d x(1.0, 0.0);
  const DenseDampedSummary summary = solver.minimize_numeric(x, [](const Eigen::Vector2d& at, Eigen::Vector2d& r) {
    r << at(0) * at(0) - 2.0, at(1) - at(0);
    return true;
  });
  EXPECT_EQ(summary.stop, DenseDampedStop::kResidualTolerance) << summary.message();
  EXPECT_NEAR(x(0), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(x(1), std::sqrt(2.0), 1e-12);
}

TEST(DenseDampedSolver, ARankDeficientProblemStillReachesAMinimum) {
  // GIVEN one residual in two unknowns, x + y - 2: J^T J has rank 1
  DenseDampedSolver<1, 2> solver(tight_dense());
  Eigen::Vector2d x(5.0, -1.0);
  const DenseDampedSummary summary =
      solver.minimize(x, [](const Eigen::Vector2d& at, Eigen::Matrix<double, 1, 1>& r, Eigen::Matrix<double, 1, 2>* j) {
        r(0) = at(0) + at(1) - 2.0;
        if (j) *j << 1.0, 1.0;
        return true;
      });
  // THEN the damping keeps every step defined and the residual vanishes;
  // the direction the data cannot see (x - y) is left where it started
  EXPECT_TRUE(summary.converged()) << summary.message();
  EXPECT_NEAR(x(0) + x(1), 2.0, 1e-9);
  EXPECT_NEAR(x(0) - x(1), 6.0, 1e-9);
}

TEST(DenseDampedSolver, AProblemWithoutARootSaysItFoundOnlyAMinimum) {
  // GIVEN r = x^2 + 1, which never vanishes, asked for a root
  DenseDampedOptions o = tight_dense();
  o.residual_tolerance = 1e-9;
  DenseDampedSolver<1, 1> solver(o);
  Eigen::Matrix<double, 1, 1> x(2.0);
  const DenseDampedSummary summary = solver.minimize_numeric(
      x, [](const Eigen::Matrix<double, 1, 1>& at, Eigen::Matrix<double, 1, 1>& r) {
        r(0) = at(0) * at(0) + 1.0;
        return true;
      });
  // THEN it stops at the least-squares minimum x = 0, chi2 = 1, and says it
  // was not a root
  EXPECT_NE(summary.stop, DenseDampedStop::kResidualTolerance) << summary.message();
  EXPECT_NEAR(summary.final_chi2, 1.0, 1e-9);
  EXPECT_NEAR(x(0), 0.0, 1e-4);
}

TEST(DenseDampedSolver, AStartOutsideTheModelIsReportedAndLeftAlone) {
  DenseDampedSolver<1, 1> solver(tight_dense());
  Eigen::Matrix<double, 1, 1> x(-1.0);
  const DenseDampedSummary summary = solver.minimize(
      x, [](const Eigen::Matrix<double, 1, 1>& at, Eigen::Matrix<double, 1, 1>& r, Eigen::Matrix<double, 1, 1>* j) {
        if (!(at(0) > 0.0)) return false;
        r(0) = std::log(at(0));
        if (j) (*j)(0) = 1.0 / at(0);
        return true;
      });
  EXPECT_EQ(summary.stop, DenseDampedStop::kNotEvaluable);
  EXPECT_EQ(summary.trials, 0);
  EXPECT_EQ(x(0), -1.0);
  EXPECT_NE(summary.message().find("cannot be evaluated"), std::string::npos);
}

TEST(DenseDampedSolver, TrialsOutsideTheModelAreRefusedAndEveryAcceptedPointIsInside) {
  // GIVEN r = x + 1, defined only for x > 0: its minimum lies outside
  DenseDampedSolver<1, 1> solver(tight_dense());
  Eigen::Matrix<double, 1, 1> x(3.0);
  int outside = 0;
  const DenseDampedSummary summary = solver.minimize(
      x, [&](const Eigen::Matrix<double, 1, 1>& at, Eigen::Matrix<double, 1, 1>& r, Eigen::Matrix<double, 1, 1>* j) {
        if (!(at(0) > 0.0)) return ++outside, false;
        r(0) = at(0) + 1.0;
        if (j) (*j)(0) = 1.0;
        return true;
      });
  // THEN it crawls to the edge, refusing the trials beyond it, and ends inside
  EXPECT_GT(outside, 0);
  EXPECT_GT(x(0), 0.0);
  EXPECT_LT(x(0), 1e-3);
  EXPECT_LT(summary.accepted, summary.trials) << summary.message();
}

TEST(DenseDampedSolver, TheTrialLimitIsHonouredAndNamed) {
  DenseDampedOptions o = tight_dense();
  o.max_trials = 3;
  Solver2 solver(o);
  Eigen::Vector2d x(-1.2, 1.0);
  const DenseDampedSummary summary = solver.minimize(x, rosenbrock_dense);
  EXPECT_EQ(summary.stop, DenseDampedStop::kMaxTrials);
  EXPECT_EQ(summary.trials, 3);
  EXPECT_FALSE(summary.converged());
  EXPECT_LE(summary.final_chi2, summary.initial_chi2);
}

TEST(DenseDampedSolver, ABoundStopsItsCoordinateAndTheOthersTakeTheirBestStepForIt) {
  // GIVEN r = (x - 3, y - x) with x bounded above by 1: the constrained
  // minimum is (1, 1)
  Solver2 solver(tight_dense());
  solver.set_bounds(Eigen::Vector2d(-10.0, -10.0), Eigen::Vector2d(1.0, 10.0));
  Eigen::Vector2d x(0.0, 0.0);
  const DenseDampedSummary summary =
      solver.minimize(x, [](const Eigen::Vector2d& at, Eigen::Vector2d& r, Eigen::Matrix2d* j) {
        r << at(0) - 3.0, at(1) - at(0);
        if (j) *j << 1.0, 0.0, -1.0, 1.0;
        return true;
      });
  EXPECT_TRUE(summary.converged()) << summary.message();
  EXPECT_EQ(x(0), 1.0);
  EXPECT_NEAR(x(1), 1.0, 1e-6);
}

TEST(DenseDampedSolver, DynamicSizesOnAManifold) {
  // GIVEN a point on the unit circle (as a 2-vector), moved by an angle,
  // fitted to the direction (0, 1): residual = point - (0, 1)
  using Dynamic = DenseDampedSolver<Eigen::Dynamic, Eigen::Dynamic>;
  Dynamic solver(tight_dense());
  Eigen::Vector2d point(1.0, 0.0);
  auto evaluate = [](const Eigen::Vector2d& p, Eigen::VectorXd& r, Eigen::MatrixXd* j) {
    r = p - Eigen::Vector2d(0.0, 1.0);
    if (j) *j = Eigen::Vector2d(-p(1), p(0));  // d p / d angle
    return true;
  };
  auto retract = [](const Eigen::Vector2d& p, const Eigen::VectorXd& step, Eigen::Vector2d& out) {
    out = Eigen::Rotation2Dd(step(0)) * p;
  };
  const DenseDampedSummary summary = solver.minimize_on_manifold(point, evaluate, retract);
  EXPECT_TRUE(summary.converged()) << summary.message();
  EXPECT_NEAR(point(0), 0.0, 1e-6);
  EXPECT_NEAR(point(1), 1.0, 1e-6);
  EXPECT_NEAR(point.norm(), 1.0, 1e-12);
}

}  // namespace
}  // namespace cdpr
