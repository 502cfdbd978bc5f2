#pragma once
// Which sensor readings of a fitted calibration are gross errors (a slipped
// cable, a bus glitch, a platform not yet at rest): the test that decides
// rejection after the robust fit (solver/calibration/calibrate.h).
//
// Each reading's whitened residual (residual / the sensor's sigma of
// robot.toml) is divided by the spread of all readings of its kind (encoder
// or load cell): 1.4826 times their median absolute value, a spread that a
// minority of gross errors does not move, taken as 1 when it is smaller
// (the sigmas of robot.toml are the floor: a fit's residuals are a little
// smaller than the noise). A reading is a gross error when that normalised
// residual exceeds the threshold: noise with the right sigma exceeds 5 once
// in 1.7 million readings, so clean rows are practically never rejected,
// while data noisier than robot.toml says (or a model that does not fit
// everywhere) raises the spread and the bar with it rather than rejecting
// whole swathes of rows.

#include <vector>

#include "solver/model/calibration.h"
#include "solver/nls/problem.h"

namespace cdpr {

// One reading's whitened residual at the current values of a problem.
struct ReadingResidual {
  int row = 0;  // sample id
  SensorKind sensor = SensorKind::kEncoder;
  int cable = 0;
  double whitened = 0.0;
};

// The robust spread of each kind, by which residuals are normalised.
struct ReadingSpreads {
  double encoder = 1.0, force = 1.0;
  double of(SensorKind kind) const { return kind == SensorKind::kEncoder ? encoder : force; }
};
ReadingSpreads reading_spreads(const std::vector<ReadingResidual>& residuals);

// Readings whose normalised residual exceeds threshold_sigma, each with that
// normalised residual as its value; worst first.
std::vector<SensorReading> gross_errors(const std::vector<ReadingResidual>& residuals, double threshold_sigma);

// The largest normalised residual (0 when there are none).
double largest_normalised_residual(const std::vector<ReadingResidual>& residuals);

// Clears the group of a reading left alone in its suspect group
// (SensorReading::group): a later change of the set left out (the swap test)
// may have taken the others back in, and a group of one is a reading named alone.
void settle_groups(std::vector<SensorReading>& readings);

// The final test of the readings a fit left out: `candidates` (their value
// the normalised residual that flagged them, NaN for a reading left out only
// because its whole row was a hypothesis) against `predicted`, each as the
// refit without it predicts it (a leave-one-out residual). A reading stays
// out when the refit predicts it beyond bar_sigma, or when the refit failed
// or has no prediction for it and it was flagged by its own residual; it
// then carries the prediction's size when its own was unknown. Of a
// hypothesis row (all its readings left out, so each is predicted from the
// row's pose prior alone) only the reading predicted farthest off stays
// out. A hypothesis reading nothing confirms goes back in, so no NaN is
// ever reported. A suspect group (SensorReading::group) stays out whole
// while any of its members stays out by the rules above.
std::vector<SensorReading> confirm_left_out(const std::vector<SensorReading>& candidates,
                                            const std::vector<SensorReading>& predicted, bool refit_ok,
                                            double bar_sigma);

}  // namespace cdpr
