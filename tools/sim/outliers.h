#pragma once
// Gross errors in simulated readings: what a slipped cable, a bus glitch or
// a platform not yet at rest does to one row (sample) of a data set. Planted
// after the measurement, from their own random streams (sim/stream_purpose.h),
// so a data set with outliers has the same poses and noise as the one without.
//
// Rows are chosen without replacement: round(fraction * rows), at least one
// when the fraction is positive. An encoder outlier adds +-U(min, max) metres
// to one cable's reading (cable uniform); a force spike adds +-U(min, max)
// newtons to the load cell.

#include <cstdint>
#include <vector>

#include "solver/model/calibration.h"
#include "solver/model/sample.h"

namespace cdpr::sim {

struct GrossErrors {
  double encoder_fraction = 0.0;  // of the rows, one encoder each
  double encoder_min_m = 0.5, encoder_max_m = 2.0;
  double force_fraction = 0.0;    // of the rows
  double force_min_n = 50.0, force_max_n = 500.0;
};

// Changes `samples` in place; returns what was planted (value: reading - true).
std::vector<SensorReading> plant_gross_errors(const GrossErrors& errors, std::uint64_t seed, int reference_cable,
                                              std::vector<Sample>& samples);

}  // namespace cdpr::sim
