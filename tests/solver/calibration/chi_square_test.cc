// The chi-square tail the model-discrepancy workflow judges remaining
// structure with (solver/diagnosis/diagnosis.h), against tabulated quantiles.
#include <cmath>

#include <gtest/gtest.h>

#include "solver/calibration/chi_square.h"

namespace cdpr {
namespace {

TEST(ChiSquareUpperTail, MatchesTabulatedQuantiles) {
  // P(X > x) for the 5 % and 0.1 % points of chi-square tables.
  EXPECT_NEAR(chi_square_upper_tail(18.307, 10), 0.05, 0.002);
  EXPECT_NEAR(chi_square_upper_tail(124.342, 100), 0.05, 0.001);
  EXPECT_NEAR(chi_square_upper_tail(149.449, 100), 0.001, 0.0002);
}

TEST(ChiSquareUpperTail, IsExactForTheFewDegreesOfFreedomOfALikelihoodRatio) {
  // Tabulated 1 % and 0.1 % points; Wilson-Hilferty is off by 10-30 % here.
  EXPECT_NEAR(chi_square_upper_tail(10.828, 1), 0.001, 1e-6);
  EXPECT_NEAR(chi_square_upper_tail(9.210, 2), 0.01, 1e-5);
  EXPECT_NEAR(chi_square_upper_tail(11.345, 3), 0.01, 1e-5);
  EXPECT_NEAR(chi_square_upper_tail(18.467, 4), 0.001, 1e-6);
  EXPECT_NEAR(chi_square_upper_tail(50.892, 30), 0.01, 1e-5);
  // The closed forms at k = 1 and 2.
  EXPECT_NEAR(chi_square_upper_tail(3.0, 1), std::erfc(std::sqrt(1.5)), 1e-15);
  EXPECT_NEAR(chi_square_upper_tail(3.0, 2), std::exp(-1.5), 1e-15);
}

TEST(ChiSquareUpperTail, IsOneAtZeroAndFallsWithX) {
  EXPECT_DOUBLE_EQ(chi_square_upper_tail(0.0, 5), 1.0);
  EXPECT_GT(chi_square_upper_tail(4.0, 5), chi_square_upper_tail(6.0, 5));
}

TEST(ScaledChiSquareUpperTail, IsAChiSquareWhenTheVarianceIsTwiceTheMean) {
  // chi-square(100): mean 100, variance 200
  EXPECT_NEAR(scaled_chi_square_upper_tail(124.342, 100.0, 200.0), 0.05, 0.001);
  EXPECT_NEAR(scaled_chi_square_upper_tail(124.342, 100.0, 0.0), 0.05, 0.001);
}

TEST(ScaledChiSquareUpperTail, MatchesAScaledChiSquareOfTheSameMeanAndVariance) {
  // 2 chi-square(50): mean 100, variance 400; chi-square(50) exceeds 67.505 with p 0.05
  EXPECT_NEAR(scaled_chi_square_upper_tail(2.0 * 67.505, 100.0, 400.0), 0.05, 0.002);
  // a wider spread makes the same excess less significant
  EXPECT_GT(scaled_chi_square_upper_tail(130.0, 100.0, 400.0), scaled_chi_square_upper_tail(130.0, 100.0, 200.0));
}

}  // namespace
}  // namespace cdpr
