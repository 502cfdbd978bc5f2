#include "src/report/ticks.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cdpr::report {
namespace {

// The mantissa of a 1-2-5 step: 1, 2 or 5.
double mantissa(double step) { return step / std::pow(10.0, std::floor(std::log10(step) + 1e-9)); }

TEST(NiceTicks, StepIsOneTwoOrFiveTimesAPowerOfTen) {
  // GIVEN ranges of residuals in metres, newtons and sample numbers
  for (auto [lo, hi] : {std::pair{-0.117, 0.019}, {-0.006546, 0.01088}, {0.0, 44.0}, {130.0, 1210.0}, {-3e-5, 7e-5}}) {
    // WHEN ticks are chosen
    const Ticks t = nice_ticks(lo, hi);
    // THEN the step is on the 1-2-5 series, the ticks hold the data and are at most 6
    const double m = mantissa(t.step);
    EXPECT_TRUE(std::abs(m - 1) < 1e-9 || std::abs(m - 2) < 1e-9 || std::abs(m - 5) < 1e-9) << lo << " " << t.step;
    EXPECT_LE(t.lo, lo);
    EXPECT_GE(t.hi, hi);
    EXPECT_LE(t.values.size(), 6u);
    EXPECT_GE(t.values.size(), 2u);
    EXPECT_DOUBLE_EQ(t.values.front(), t.lo);
    EXPECT_NEAR(t.values.back(), t.hi, 1e-12 * std::abs(t.hi) + 1e-15);
  }
}

TEST(NiceTicks, ResidualRangeGetsRoundTicks) {
  // GIVEN encoder residuals from -6.5 to +10.9 mm
  const Ticks t = nice_ticks(-6.546, 10.88);
  // THEN the axis runs -10 to 15 in steps of 5
  EXPECT_DOUBLE_EQ(t.step, 5.0);
  EXPECT_DOUBLE_EQ(t.lo, -10.0);
  EXPECT_DOUBLE_EQ(t.hi, 15.0);
  EXPECT_EQ(t.values.size(), 6u);
}

TEST(NiceTicks, ExactTickValuesAreNotWidened) {
  const Ticks t = nice_ticks(0.0, 40.0, 4);
  EXPECT_DOUBLE_EQ(t.lo, 0.0);
  EXPECT_DOUBLE_EQ(t.hi, 40.0);
  EXPECT_DOUBLE_EQ(t.step, 10.0);
}

TEST(NiceTicks, SingleValueIsWidened) {
  const Ticks t = nice_ticks(3.0, 3.0);
  EXPECT_LT(t.lo, 3.0);
  EXPECT_GT(t.hi, 3.0);
  const Ticks zero = nice_ticks(0.0, 0.0);
  EXPECT_LT(zero.lo, 0.0);
  EXPECT_GT(zero.hi, 0.0);
}

TEST(TickLabel, ShowsTheDecimalsTheStepNeeds) {
  EXPECT_EQ(tick_label(0.005, 0.005), "0.005");
  EXPECT_EQ(tick_label(-0.01, 0.005), "-0.010");
  EXPECT_EQ(tick_label(150.0, 50.0), "150");
  EXPECT_EQ(tick_label(0.2, 0.2), "0.2");
  EXPECT_EQ(tick_label(-1e-17, 0.1), "0.0");  // never "-0.0"
}

}  // namespace
}  // namespace cdpr::report
