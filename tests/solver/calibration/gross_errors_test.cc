#include "solver/calibration/gross_errors.h"

#include <cmath>
#include <limits>

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

TEST(GrossErrors, LeftOutReadingsAreConfirmedByTheRefitsPrediction) {
  // GIVEN four readings left out: two flagged by their own residual, two
  // only because their row was a hypothesis (value unknown)
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  const std::vector<SensorReading> candidates{{1, SensorKind::kEncoder, 0, 40.0},
                                              {2, SensorKind::kEncoder, 3, -12.0},
                                              {5, SensorKind::kEncoder, 1, unknown},
                                              {5, SensorKind::kForce, 0, unknown}};
  // and the refit predicting three of them: one far off, two within the bar
  const std::vector<SensorReading> predicted{{1, SensorKind::kEncoder, 0, 2.0},
                                             {2, SensorKind::kEncoder, 3, -30.0},
                                             {5, SensorKind::kEncoder, 1, 1.5}};
  // WHEN confirmed at 5 sigma
  const std::vector<SensorReading> confirmed = confirm_left_out(candidates, predicted, true, 5.0);
  // THEN only the one predicted far off stays out; the hypothesis reading
  // without a prediction goes back in rather than being reported as NaN
  ASSERT_EQ(confirmed.size(), 1u);
  EXPECT_EQ(confirmed[0].row, 2);
  EXPECT_DOUBLE_EQ(confirmed[0].value, -12.0);
}

TEST(GrossErrors, AFailedRefitKeepsOnlyReadingsFlaggedByTheirOwnResidual) {
  // GIVEN a flagged reading and a row hypothesis whose refit failed
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  const std::vector<SensorReading> candidates{{3, SensorKind::kForce, 0, -70.0},
                                              {4, SensorKind::kEncoder, 2, unknown}};
  // WHEN confirmed without a usable refit (its predictions, if any, are not trusted)
  const std::vector<SensorReading> confirmed =
      confirm_left_out(candidates, {{4, SensorKind::kEncoder, 2, unknown}}, false, 5.0);
  // THEN the flagged reading stays out with its own residual and no NaN is left
  ASSERT_EQ(confirmed.size(), 1u);
  EXPECT_EQ(confirmed[0].row, 3);
  EXPECT_DOUBLE_EQ(confirmed[0].value, -70.0);
}

TEST(GrossErrors, OfAHypothesisRowOnlyTheReadingPredictedFarthestOffStaysOut) {
  // GIVEN a row hypothesis: two of its readings predicted beyond the bar
  // (from the pose prior alone, good readings look bad too)
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  const std::vector<SensorReading> candidates{{6, SensorKind::kEncoder, 1, unknown},
                                              {6, SensorKind::kForce, 0, unknown}};
  // WHEN confirmed
  const std::vector<SensorReading> confirmed = confirm_left_out(
      candidates, {{6, SensorKind::kEncoder, 1, 25.0}, {6, SensorKind::kForce, 0, -12.0}}, true, 5.0);
  // THEN only the farthest stays out, reported with the predicted size
  ASSERT_EQ(confirmed.size(), 1u);
  EXPECT_EQ(confirmed[0].sensor, SensorKind::kEncoder);
  EXPECT_DOUBLE_EQ(confirmed[0].value, 25.0);
}

TEST(GrossErrors, ASuspectGroupStaysOutWholeWhileOneOfItsMembersDoes) {
  // GIVEN a row's suspect group (encoder 3 or the load cell) and another
  // row's group, of which the refit predicts only one member beyond the bar
  const std::vector<SensorReading> candidates{{6, SensorKind::kForce, 0, -22.9, 1},
                                              {6, SensorKind::kEncoder, 3, 5.9, 1},
                                              {9, SensorKind::kForce, 0, 7.0, 1},
                                              {9, SensorKind::kEncoder, 1, 6.0, 1}};
  const std::vector<SensorReading> predicted{{6, SensorKind::kForce, 0, -22.9},
                                             {6, SensorKind::kEncoder, 3, 1.2},
                                             {9, SensorKind::kForce, 0, 2.0},
                                             {9, SensorKind::kEncoder, 1, -3.0}};
  // WHEN confirmed at 5 sigma
  const std::vector<SensorReading> confirmed = confirm_left_out(candidates, predicted, true, 5.0);
  // THEN row 6's group stays out with both members (the one predicted
  // within the bar too), and row 9's, none of whose members is, goes back in
  ASSERT_EQ(confirmed.size(), 2u);
  EXPECT_EQ(confirmed[0].row, 6);
  EXPECT_EQ(confirmed[1].row, 6);
  EXPECT_EQ(confirmed[1].sensor, SensorKind::kEncoder);
  EXPECT_EQ(confirmed[1].group, 1);
}

TEST(GrossErrors, AGroupOfOneIsAReadingNamedAlone) {
  // GIVEN a group whose other member was taken back in, and a whole group
  std::vector<SensorReading> readings{{4, SensorKind::kForce, 0, 9.0, 1},
                                      {7, SensorKind::kEncoder, 0, 8.0, 1},
                                      {7, SensorKind::kEncoder, 2, 7.0, 1}};
  // WHEN settled
  settle_groups(readings);
  // THEN only the whole group keeps its number
  EXPECT_EQ(readings[0].group, 0);
  EXPECT_EQ(readings[1].group, 1);
  EXPECT_EQ(readings[2].group, 1);
}

}  // namespace
}  // namespace cdpr
