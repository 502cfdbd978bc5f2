// Which of two fits from different starts calibrate() keeps
// (solver/calibration/start_selection.h).
#include <gtest/gtest.h>

#include "solver/calibration/start_selection.h"

namespace cdpr {
namespace {

CalibrationResult fit_of(int rows, int refused, double chi_square) {
  CalibrationResult r;
  r.ok = true;
  r.calibration.samples = rows;
  for (int k = 0; k < refused; ++k) r.rejected_samples.push_back(k);
  r.chi_square = chi_square;
  return r;
}

TEST(StartSelection, AFitOfEveryRowDoesNotWinWithAnyChiSquare) {
  // GIVEN the small robot's informative plan of seed 23 (nominal anchors
  // 2 m off), one row holding a nearly slack cable: the fit from the true
  // anchors refuses that row at the start and reaches chi2 176.6 (errors
  // within their sigmas); a start at a rigid fit's anchors fits all 34 rows
  // and ends 14 m off with chi2 4.65e10
  const CalibrationResult from_truth = fit_of(33, 1, 176.6);
  const CalibrationResult every_row = fit_of(34, 0, 4.65e10);
  // THEN the fit of every row is not the better one, and the other is
  EXPECT_FALSE(better_fit(every_row, from_truth, 5.0));
  EXPECT_TRUE(better_fit(from_truth, every_row, 5.0));
}

TEST(StartSelection, ARowRefusedAtTheStartCostsAllItsReadings) {
  // GIVEN two fits, one refusing a row whose readings the other fits at a
  // chi-square cost of 100 (less than 5 readings at 25 each)
  const CalibrationResult refused = fit_of(33, 1, 200.0);
  const CalibrationResult kept = fit_of(34, 0, 300.0);
  // THEN the one that kept the row is better
  EXPECT_DOUBLE_EQ(start_score(refused, 5.0), 200.0 + 5 * 25.0);
  EXPECT_TRUE(better_fit(kept, refused, 5.0));
}

}  // namespace
}  // namespace cdpr
