#include "solver/nls/loss.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "solver/nls/factor_support.h"

namespace cdpr {
namespace {

TEST(Loss, PlainLeastSquaresWhenWidthNotPositive) {
  for (double width : {0.0, -1.0}) {
    // GIVEN no Huber width; THEN cost is r^2/2 and nothing is rescaled
    const Loss loss{width};
    for (double r : {-100.0, -0.5, 0.0, 3.0, 1e6}) {
      EXPECT_DOUBLE_EQ(loss.cost(r), 0.5 * r * r);
      EXPECT_DOUBLE_EQ(loss.scale(r), 1.0);
    }
  }
}

TEST(Loss, HuberIsQuadraticInsideAndLinearOutside) {
  // GIVEN width k = 2
  const Loss loss{2.0};
  // THEN inside |r| <= k: r^2/2; outside: k|r| - k^2/2, continuous at the width
  EXPECT_DOUBLE_EQ(loss.cost(1.5), 0.5 * 1.5 * 1.5);
  EXPECT_DOUBLE_EQ(loss.cost(-2.0), 2.0);
  EXPECT_DOUBLE_EQ(loss.cost(10.0), 2.0 * 10.0 - 2.0);
  EXPECT_DOUBLE_EQ(loss.cost(-10.0), 2.0 * 10.0 - 2.0);
  EXPECT_NEAR(loss.cost(2.0 + 1e-9), loss.cost(2.0), 3e-9);
}

TEST(Loss, ScaledResidualCarriesTheHuberGradient) {
  // GIVEN an outlier residual r beyond the width k
  const Loss loss{1.5};
  for (double r : {-7.0, 2.0, 40.0}) {
    // WHEN the solver sees s*r with Jacobian s*J; its gradient (s*r)*(s*J) = s^2 r J
    const double s = loss.scale(r);
    // THEN that equals d cost / dr * J (numerically differentiated cost)
    const double h = 1e-6;
    const double dcost = (loss.cost(r + h) - loss.cost(r - h)) / (2 * h);
    EXPECT_NEAR(s * s * r, dcost, 1e-7) << r;
    EXPECT_LT(s, 1.0);
  }
}

TEST(Loss, CauchyRedescendsAndCarriesItsGradient) {
  // GIVEN a Cauchy loss of width 3
  const LossFunction cauchy{LossKind::kCauchy, 3.0};
  for (double r : {-50.0, -2.0, 0.5, 3.0, 400.0}) {
    // THEN the scaled residual carries d cost / dr (IRLS weight rho')
    const double s = cauchy.scale(r);
    const double h = 1e-6;
    const double dcost = (cauchy.cost(r + h) - cauchy.cost(r - h)) / (2 * h);
    EXPECT_NEAR(s * s * r, dcost, 1e-6 * std::max(1.0, std::abs(dcost))) << r;
  }
  // AND a gross error pulls less the larger it is (redescending influence)
  EXPECT_LT(std::pow(cauchy.scale(400.0), 2) * 400.0, std::pow(cauchy.scale(40.0), 2) * 40.0);
  EXPECT_NEAR(cauchy.cost(0.01), 0.5 * 0.01 * 0.01, 1e-9);
}

TEST(Loss, SharedLossFollowsItsFunction) {
  // GIVEN a Loss reading a shared function
  LossFunction function{LossKind::kHuber, 2.0};
  const Loss loss{0.0, &function};
  EXPECT_DOUBLE_EQ(loss.cost(10.0), 2.0 * 10.0 - 2.0);
  // WHEN the function changes between solves THEN the Loss follows it
  function = LossFunction{};
  EXPECT_DOUBLE_EQ(loss.cost(10.0), 50.0);
  EXPECT_DOUBLE_EQ(loss.scale(10.0), 1.0);
}

TEST(Loss, QuadraticWhereItLeavesTheResidualAsLeastSquares) {
  // GIVEN Huber of width 2, Cauchy of width 2, and plain least squares
  const LossFunction huber{LossKind::kHuber, 2.0}, cauchy{LossKind::kCauchy, 2.0}, squared{};
  for (double r : {-3.0, -2.0, -0.5, 0.0, 1.5, 2.0, 2.5}) {
    // THEN Huber is quadratic within its width, least squares everywhere,
    // Cauchy nowhere; where quadratic, cost and scale are least squares' to the bit
    EXPECT_EQ(huber.quadratic_at(r), std::abs(r) <= 2.0) << r;
    EXPECT_TRUE(squared.quadratic_at(r));
    EXPECT_FALSE(cauchy.quadratic_at(r));
    for (const LossFunction* loss : {&huber, &squared}) {
      if (!loss->quadratic_at(r)) continue;
      EXPECT_EQ(loss->cost(r), 0.5 * r * r);
      EXPECT_EQ(loss->scale(r), 1.0);
    }
  }
  // and a Loss without a shared function is a Huber of its width
  EXPECT_TRUE(Loss{0.0}.quadratic_at(1e6));
  EXPECT_FALSE(Loss{2.0}.quadratic_at(2.5));
  EXPECT_TRUE((Loss{0.0, &huber}.quadratic_at(1.5)));
}

TEST(Loss, LeastSquaresEverywhereOnlyWithoutWidthOrSharedFunction) {
  const LossFunction squared{};
  EXPECT_TRUE(Loss{0.0}.least_squares());
  EXPECT_TRUE(Loss{-1.0}.least_squares());
  EXPECT_FALSE(Loss{2.0}.least_squares());
  // a shared function may change between evaluations
  EXPECT_FALSE((Loss{0.0, &squared}.least_squares()));
}

TEST(Loss, ApplyLossOfLeastSquaresGivesTheRowByRowBits) {
  // GIVEN residuals and a Jacobian block, once under a plain Loss and once
  // under a shared least-squares function (asked row by row)
  const LossFunction squared{};
  const std::array<double, 4> start = {0.3, -1e5, 2.0 / 3.0, 0.0};
  std::array<double, 4> plain = start, shared = start;
  std::array<double, 8> plain_jacobian{}, shared_jacobian{};
  for (std::size_t i = 0; i < plain_jacobian.size(); ++i) plain_jacobian[i] = shared_jacobian[i] = 0.1 * i - 0.3;
  double* plain_blocks[] = {plain_jacobian.data()};
  double* shared_blocks[] = {shared_jacobian.data()};
  const std::array<int, 1> dims = {2};
  // WHEN the loss is applied
  const double plain_cost = apply_loss(Loss{0.0}, 4, plain.data(), plain_blocks, dims);
  const double shared_cost = apply_loss(Loss{0.0, &squared}, 4, shared.data(), shared_blocks, dims);
  // THEN the costs, residuals and rows are the same bits
  EXPECT_EQ(std::memcmp(&plain_cost, &shared_cost, sizeof(double)), 0);
  EXPECT_EQ(plain, shared);
  EXPECT_EQ(plain, start);
  EXPECT_EQ(plain_jacobian, shared_jacobian);
}

}  // namespace
}  // namespace cdpr
