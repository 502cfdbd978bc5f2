#pragma once
// Why calibrate() refuses a fit with more rows of gross errors than allowed:
// the sensors, or the model. A model that does not fit (a weightless cable
// solved as a catenary, a localisation noisier than robot.toml says) makes
// every row look bad to the robust stage, which then flags half of them;
// a sensor fault leaves a few readings per row off while the rest fits.
// So before the refusal is blamed on the sensors, each catalogued model term
// the model lacks, and each pose-noise scale the data imply, is tried: a
// robust fit with it that keeps the rows with gross errors within the limit
// explains the rows, and the refusal becomes a model misfit naming it
// (docs/robust-calibration.md step 6).

#include <functional>
#include <vector>

#include "solver/calibration/calibrate.h"

namespace cdpr {

// A robust fit of `samples` from `robot` with `options`, as calibrate() makes
// one from one start (refused when it still has too many rows with gross
// errors).
using RobustFit = std::function<CalibrationResult(const Robot&, const std::vector<Sample>&, const CalibrationOptions&)>;

// For a result refused for its gross errors (Refusal::kSensorFault): sets
// refusal to kModelMisfit with its explanation when a candidate brings the
// rows with gross errors within options.max_rejected_fraction, else leaves
// it a sensor fault with the candidates tried in refusal_evidence. Each
// candidate costs one robust fit (up to kEffectCount + 3).
void classify_refusal(const Robot& robot, const std::vector<Sample>& samples, const CalibrationOptions& options,
                      const RobustFit& fit, CalibrationResult& refused);

// The share of `rows` with a reading in result.gross_errors.
double gross_error_row_fraction(const CalibrationResult& result, std::size_t rows);

}  // namespace cdpr
