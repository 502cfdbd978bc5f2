// The chi-square tail the model-discrepancy workflow judges remaining
// structure with (solver/diagnosis.h), against tabulated quantiles.
#include <gtest/gtest.h>

#include "solver/diagnosis.h"

namespace cdpr {
namespace {

TEST(ChiSquareUpperTail, MatchesTabulatedQuantiles) {
  // P(X > x) for the 5 % and 0.1 % points of chi-square tables.
  EXPECT_NEAR(chi_square_upper_tail(18.307, 10), 0.05, 0.002);
  EXPECT_NEAR(chi_square_upper_tail(124.342, 100), 0.05, 0.001);
  EXPECT_NEAR(chi_square_upper_tail(149.449, 100), 0.001, 0.0002);
}

TEST(ChiSquareUpperTail, IsOneAtZeroAndFallsWithX) {
  EXPECT_DOUBLE_EQ(chi_square_upper_tail(0.0, 5), 1.0);
  EXPECT_GT(chi_square_upper_tail(4.0, 5), chi_square_upper_tail(6.0, 5));
}

}  // namespace
}  // namespace cdpr
