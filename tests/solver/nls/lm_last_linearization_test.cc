// LevenbergMarquardt::last_residuals and last_jacobian: the factors as the
// last solve() left them, at its solution.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lm_test_factors.h"
#include "solver/nls/factor_parameters.h"
#include "solver/nls/levenberg_marquardt.h"

namespace cdpr {
namespace {

TEST(LevenbergMarquardtLastLinearization, IsEachFactorEvaluatedAtTheSolution) {
  // GIVEN a chain x0 - x1 - x2 of 2-vectors with random linear factors, x0
  // held constant, and an exponential curve through x2
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random2 = [&]() -> Eigen::Matrix2d { return Eigen::Matrix2d::NullaryExpr([&]() { return u(rng); }); };
  Problem problem;
  for (int v = 0; v < 3; ++v) problem.add_vector(EffectKey(v), Eigen::Vector2d(u(rng), u(rng)));
  for (int v = 0; v < 2; ++v) {
    problem.add_factor(std::make_unique<test::LinearFactor>(EffectKey(v), EffectKey(v + 1), random2(), random2(),
                                                            Eigen::Vector2d(u(rng), u(rng)), 0.5));
  }
  // Nonlinear in x2: its Jacobian differs from point to point.
  for (double t : {0.1, 0.4, 0.7, 1.0}) {
    problem.add_factor(std::make_unique<test::ExpCurveFactor>(EffectKey(2), t, std::exp(0.3 * t + 0.2) + 0.01 * u(rng)));
  }
  problem.set_constant(EffectKey(0));
  LevenbergMarquardt lm(problem, {});
  // WHEN solved
  ASSERT_TRUE(lm.solve().usable());
  // THEN every factor's residuals and Jacobian blocks are what it gives at
  // the solution, and a constant variable's block is empty
  for (int f = 0; f < static_cast<int>(problem.factors().size()); ++f) {
    const Factor& factor = *problem.factors()[f];
    const std::size_t keys = factor.keys().size();
    std::vector<std::vector<double>> blocks(keys);
    std::vector<double*> jacobians(keys);
    for (std::size_t k = 0; k < keys; ++k) {
      blocks[k].assign(static_cast<std::size_t>(factor.residual_dim()) * 2, 0.0);
      jacobians[k] = blocks[k].data();
    }
    std::vector<double> residual(factor.residual_dim());
    double cost = 0.0;
    ASSERT_TRUE(factor.evaluate(parameter_blocks(problem, factor).data(), residual.data(), jacobians.data(), &cost));
    const std::span<const double> last = lm.last_residuals(f);
    EXPECT_EQ(std::vector<double>(last.begin(), last.end()), residual) << "factor " << f;
    for (std::size_t k = 0; k < keys; ++k) {
      const std::span<const double> block = lm.last_jacobian(f, static_cast<int>(k));
      if (factor.keys()[k] == EffectKey(0)) {
        EXPECT_TRUE(block.empty()) << "factor " << f;
        continue;
      }
      EXPECT_EQ(std::vector<double>(block.begin(), block.end()), blocks[k]) << "factor " << f << " key " << k;
    }
  }
}

}  // namespace
}  // namespace cdpr
