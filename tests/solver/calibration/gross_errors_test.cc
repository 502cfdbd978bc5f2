#include "solver/calibration/gross_errors.h"

#include <gtest/gtest.h>

namespace cdpr {
namespace {

std::vector<ReadingResidual> clean_encoders(int rows, double size) {
  std::vector<ReadingResidual> out;
  for (int k = 0; k < rows; ++k) {
    for (int i = 0; i < kCableCount; ++i) out.push_back({k, SensorKind::kEncoder, i, (i % 2 ? size : -size)});
    out.push_back({k, SensorKind::kForce, 0, 0.5 * size});
  }
  return out;
}

TEST(GrossErrors, OnlyReadingsBeyondTheThresholdWorstFirst) {
  // GIVEN residuals of the noise's size and two gross errors
  std::vector<ReadingResidual> residuals = clean_encoders(20, 0.8);
  residuals[7].whitened = 60.0;   // row 1, encoder 2
  residuals[14].whitened = -90.0; // row 2, force
  // WHEN tested at 5 sigma
  const std::vector<SensorReading> flagged = gross_errors(residuals, 5.0);
  // THEN both, worst first, named by row, sensor and cable
  ASSERT_EQ(flagged.size(), 2u);
  EXPECT_EQ(flagged[0].row, 2);
  EXPECT_EQ(flagged[0].sensor, SensorKind::kForce);
  EXPECT_DOUBLE_EQ(flagged[0].value, -90.0);
  EXPECT_EQ(flagged[1].row, 1);
  EXPECT_EQ(flagged[1].cable, 2);
}

TEST(GrossErrors, SpreadFloorsAtTheSigmasAndGrowsWithNoisierData) {
  // GIVEN readings four times noisier than the sigmas say
  std::vector<ReadingResidual> residuals = clean_encoders(20, 4.0);
  residuals[0].whitened = 15.0;  // 3.75 of their own spread: not gross
  // THEN the spread is theirs and nothing is flagged at 5
  EXPECT_NEAR(reading_spreads(residuals).encoder, 1.4826 * 4.0, 1e-9);
  EXPECT_TRUE(gross_errors(residuals, 5.0).empty());
  // AND residuals smaller than the sigmas keep the sigmas as the spread
  EXPECT_DOUBLE_EQ(reading_spreads(clean_encoders(20, 0.1)).encoder, 1.0);
}

}  // namespace
}  // namespace cdpr
