// LevenbergMarquardt::covariance: marginal blocks of (J^T J)^-1.
#include <random>

#include <gtest/gtest.h>

#include "dense_gauss_newton.h"
#include "lm_test_factors.h"
#include "solver/nls/levenberg_marquardt.h"

namespace cdpr {
namespace {

// A linear-Gaussian chain x0 - x1 - ... - x5 (2-vectors) with random
// coefficients, a prior-like factor at each end and one long-range link.
Problem linear_problem(int variables) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random2 = [&]() -> Eigen::Matrix2d { return Eigen::Matrix2d::NullaryExpr([&]() { return u(rng); }); };
  Problem problem;
  for (int v = 0; v < variables; ++v) problem.add_vector(EffectKey(v), Eigen::Vector2d(u(rng), u(rng)));
  for (int v = 0; v + 1 < variables; ++v) {
    problem.add_factor(std::make_unique<test::LinearFactor>(EffectKey(v), EffectKey(v + 1), random2(), random2(),
                                                            Eigen::Vector2d(u(rng), u(rng)), 0.1 + 0.1 * v));
  }
  problem.add_factor(std::make_unique<test::LinearFactor>(EffectKey(0), EffectKey(variables - 1),
                                                          Eigen::Matrix2d::Identity(), 0.5 * random2(),
                                                          Eigen::Vector2d(1, 2), 0.05));
  return problem;
}

TEST(LevenbergMarquardtCovariance, EqualsTheDenseInverseOfTheInformationMatrix) {
  // GIVEN a solved linear-Gaussian problem
  Problem problem = linear_problem(6);
  LevenbergMarquardt lm(problem, {});
  ASSERT_TRUE(lm.solve().usable());
  // WHEN asking for the joint marginal of x4 and x1, in that order
  const Eigen::MatrixXd covariance = lm.covariance({EffectKey(4), EffectKey(1)});
  // THEN it is that block of the dense (J^T J)^-1
  const test::DenseLinearisation lin = test::linearise_dense(problem);
  const Eigen::MatrixXd full = (lin.jacobian.transpose() * lin.jacobian).inverse();
  Eigen::MatrixXd expected(4, 4);
  const int idx[4] = {8, 9, 2, 3};  // columns of x4 then x1 in problem order
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) expected(i, j) = full(idx[i], idx[j]);
  }
  ASSERT_EQ(covariance.rows(), 4);
  EXPECT_LT((covariance - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff())
      << covariance << "\nexpected\n" << expected;
}

TEST(LevenbergMarquardtCovariance, PoseCovarianceIsInTangentCoordinates) {
  // GIVEN one pose with only a prior of sigma_p = 0.1 m, sigma_r = 0.02 rad
  Problem problem;
  Pose measured;
  measured.position_world = Eigen::Vector3d(1, 2, 3);
  measured.world_R_platform = so3_exp(Eigen::Vector3d(0.1, 0.2, 0.3));
  problem.add_pose(PoseKey(0), measured);
  problem.add_factor(std::make_unique<test::SE3PriorFactor>(PoseKey(0), measured, 0.1, 0.02));
  LevenbergMarquardt lm(problem, {});
  ASSERT_TRUE(lm.solve().usable());
  // THEN its covariance is diag(sigma_p^2 x3, sigma_r^2 x3) (Jr^-1(0) = I)
  const Eigen::MatrixXd covariance = lm.covariance({PoseKey(0)});
  Eigen::VectorXd expected(6);
  expected << 0.01, 0.01, 0.01, 4e-4, 4e-4, 4e-4;
  EXPECT_LT((covariance - Eigen::MatrixXd(expected.asDiagonal())).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LevenbergMarquardtCovariance, EmptyWhenTheInformationMatrixIsSingular) {
  // GIVEN x0 constrained only through x0 + x1 (one 2-d factor on two 2-d unknowns)
  Problem problem;
  problem.add_vector(EffectKey(0), Eigen::Vector2d(0, 0));
  problem.add_vector(EffectKey(1), Eigen::Vector2d(0, 0));
  problem.add_factor(std::make_unique<test::LinearFactor>(EffectKey(0), EffectKey(1), Eigen::Matrix2d::Identity(),
                                                          Eigen::Matrix2d::Identity(), Eigen::Vector2d(1, 1), 1.0));
  LevenbergMarquardt lm(problem, {});
  ASSERT_TRUE(lm.solve().usable());
  // THEN no covariance is claimed
  EXPECT_EQ(lm.covariance({EffectKey(0)}).size(), 0);
}

}  // namespace
}  // namespace cdpr
