// The studentised test of the kept readings (hidden_gross_errors) names
// the same readings, with the same values, whether or not it trusts the
// fit's own linearisation to rule rows out (FittedRow::largest_studentised).
#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "solver/calibration/calibrate.h"
#include "solver/calibration/row_attribution.h"

namespace cdpr {
namespace {

sim::DatasetConfig large_ten_metres_off(int poses, std::uint64_t seed) {
  sim::DatasetConfig c;
  c.pose_count = poses;
  c.seed = seed;
  c.anchor_perturbation_m = 10.0;
  c.segments = 400;
  return c;
}

// Expects the same readings named with the screen and without; returns how
// many it named over all bars.
std::size_t readings_named_with_and_without_the_screen(const sim::DatasetConfig& config) {
  const auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data) << data.error();
  if (!data) return 0;
  // Least squares: the gross errors stay in the fit, for the test to find.
  CalibrationOptions options;
  options.robust = false;
  const CalibrationResult fit = calibrate(data->nominal, data->samples, options);
  EXPECT_TRUE(fit.ok) << fit.message;
  int screened = 0;
  for (const FittedRow& row : fit.fitted_rows) screened += std::isfinite(row.largest_studentised) ? 1 : 0;
  EXPECT_GE(screened, static_cast<int>(fit.fitted_rows.size()) - 2);
  CalibrationResult unscreened = fit;
  for (FittedRow& row : unscreened.fitted_rows) row.largest_studentised = std::numeric_limits<double>::infinity();
  std::size_t named = 0;
  for (double bar : {0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 6.0}) {
    const std::vector<SensorReading> with = hidden_gross_errors(data->nominal, options, fit, bar);
    const std::vector<SensorReading> without = hidden_gross_errors(data->nominal, options, unscreened, bar);
    named += with.size();
    EXPECT_EQ(with.size(), without.size()) << "bar " << bar;
    for (std::size_t i = 0; i < std::min(with.size(), without.size()); ++i) {
      EXPECT_EQ(with[i].row, without[i].row);
      EXPECT_EQ(with[i].sensor, without[i].sensor);
      EXPECT_EQ(with[i].cable, without[i].cable);
      EXPECT_EQ(with[i].value, without[i].value);  // bit for bit: the same evaluation
    }
  }
  return named;
}

TEST(HiddenGrossErrors, TheFitsOwnLinearisationRulesOutOnlyRowsWithNothingToName) {
  // GIVEN least-squares fits of clean data and of data with gross errors in
  // 5 % of the rows' encoders and 5 % of their load cells
  // WHEN the kept readings are tested at bars from 0.5 to 6 sigma, rows
  // screened by the fit's linearisation and every row evaluated again
  // THEN both name the same readings with the same values, and the screen
  // had a value for nearly every row
  readings_named_with_and_without_the_screen(large_ten_metres_off(35, 5));
  sim::DatasetConfig gross = large_ten_metres_off(35, 39);
  gross.gross_errors.encoder_fraction = 0.05;
  gross.gross_errors.force_fraction = 0.05;
  EXPECT_GT(readings_named_with_and_without_the_screen(gross), 0u);
}

}  // namespace
}  // namespace cdpr
