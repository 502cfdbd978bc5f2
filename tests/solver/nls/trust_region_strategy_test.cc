// The trust-region rule alone: which steps it takes, how the radius grows
// and shrinks, and its limits.
#include "solver/nls/trust_region_strategy.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace cdpr {
namespace {

TrustRegionOptions options(double initial, double max = 1e16, double min = 1e-32) {
  TrustRegionOptions o;
  o.initial_radius = initial;
  o.max_radius = max;
  o.min_radius = min;
  return o;
}

TEST(TrustRegionStrategy, StartsAtTheInitialRadius) {
  const TrustRegionStrategy strategy(options(1e3));
  EXPECT_EQ(strategy.radius(), 1e3);
  EXPECT_EQ(strategy.damping(), 1e-3);
  EXPECT_FALSE(strategy.collapsed());
}

TEST(TrustRegionStrategy, APerfectModelTriplesTheRadius) {
  // GIVEN a step whose actual decrease is what the model predicted (rho = 1)
  TrustRegionStrategy strategy(options(1.0));
  // WHEN it is judged, THEN it is taken and the radius grows by the maximum factor 3
  EXPECT_TRUE(strategy.judge_step(10.0, 6.0, 4.0));
  EXPECT_DOUBLE_EQ(strategy.step_quality(), 1.0);
  EXPECT_DOUBLE_EQ(strategy.radius(), 3.0);
}

TEST(TrustRegionStrategy, AHalfRightModelKeepsTheRadius) {
  // rho = 1/2: 1 - (2 rho - 1)^3 = 1, the radius stays
  TrustRegionStrategy strategy(options(5.0));
  EXPECT_TRUE(strategy.judge_step(10.0, 8.0, 4.0));
  EXPECT_DOUBLE_EQ(strategy.radius(), 5.0);
}

TEST(TrustRegionStrategy, APoorButPositiveGainIsTakenAndShrinksTheRadius) {
  // GIVEN rho = 0.1: the step is taken (above 1e-3), the radius divided by
  // 1 - (2 * 0.1 - 1)^3 = 1.512
  TrustRegionStrategy strategy(options(1.512));
  EXPECT_TRUE(strategy.judge_step(10.0, 9.6, 4.0));
  EXPECT_NEAR(strategy.radius(), 1.0, 1e-12);
}

TEST(TrustRegionStrategy, RefusesGainsBelowTheMinimumRelativeDecrease) {
  TrustRegionStrategy strategy(options(8.0));
  // rho = 5e-4 is not enough (minimum 1e-3); a cost that rises is refused
  EXPECT_FALSE(strategy.judge_step(1.0, 1.0 - 5e-4, 1.0));
  EXPECT_FALSE(strategy.judge_step(1.0, 2.0, 1.0));
  EXPECT_LT(strategy.step_quality(), 0.0);
}

TEST(TrustRegionStrategy, RefusalsShrinkTheRadiusByNuDoublingEachTime) {
  // GIVEN radius 64, WHEN three steps are refused in a row
  TrustRegionStrategy strategy(options(64.0));
  EXPECT_FALSE(strategy.judge_step(1.0, 2.0, 1.0));
  EXPECT_EQ(strategy.radius(), 32.0);  // / 2
  strategy.reject_step();               // a step that could not be computed counts the same
  EXPECT_EQ(strategy.radius(), 8.0);   // / 4
  EXPECT_FALSE(strategy.judge_step(1.0, 2.0, 1.0));
  EXPECT_EQ(strategy.radius(), 1.0);   // / 8
  // THEN an accepted step resets nu: the next refusal halves again
  EXPECT_TRUE(strategy.judge_step(10.0, 8.0, 4.0));  // rho = 1/2, radius stays 1
  EXPECT_FALSE(strategy.judge_step(1.0, 2.0, 1.0));
  EXPECT_EQ(strategy.radius(), 0.5);
}

TEST(TrustRegionStrategy, AnUnevaluableCandidateIsRefused) {
  TrustRegionStrategy strategy(options(4.0));
  EXPECT_FALSE(strategy.judge_step(1.0, std::numeric_limits<double>::quiet_NaN(), 1.0));
  EXPECT_FALSE(strategy.judge_step(1.0, std::numeric_limits<double>::infinity(), 1.0));
  EXPECT_EQ(strategy.radius(), 0.5);
}

TEST(TrustRegionStrategy, NoPredictedDecreaseIsRefusedWhateverTheCost) {
  // A model that predicts no decrease says the step is not a descent step.
  TrustRegionStrategy strategy(options(4.0));
  EXPECT_FALSE(strategy.judge_step(10.0, 1.0, 0.0));
  EXPECT_FALSE(strategy.judge_step(10.0, 1.0, -1.0));
  EXPECT_EQ(strategy.step_quality(), 0.0);
  EXPECT_EQ(strategy.radius(), 0.5);
}

TEST(TrustRegionStrategy, TheRadiusNeverExceedsItsMaximum) {
  TrustRegionStrategy strategy(options(1e8, 1e9));
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(strategy.judge_step(10.0, 6.0, 4.0));
  EXPECT_EQ(strategy.radius(), 1e9);
}

TEST(TrustRegionStrategy, CollapsesBelowTheMinimumRadius) {
  // GIVEN radius 1 and minimum 1e-3: refusals divide by 2, 4, 8, 16 (total 1024)
  TrustRegionStrategy strategy(options(1.0, 1e16, 1e-3));
  for (int i = 0; i < 3; ++i) {
    strategy.reject_step();
    EXPECT_FALSE(strategy.collapsed());
  }
  strategy.reject_step();
  EXPECT_TRUE(strategy.collapsed());
}

TEST(TrustRegionStrategy, ResetRestoresTheStart) {
  TrustRegionStrategy strategy(options(16.0));
  strategy.reject_step();
  strategy.reject_step();
  strategy.reset();
  EXPECT_EQ(strategy.radius(), 16.0);
  strategy.reject_step();
  EXPECT_EQ(strategy.radius(), 8.0);  // nu back at 2
}

}  // namespace
}  // namespace cdpr
