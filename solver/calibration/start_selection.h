#pragma once
// Multi-start for calibrate(): when a fit may not be at the minimum a fit
// from the true anchors would reach, other starts are fitted too and the
// fit that explains the readings best is kept. Fits from different starts
// may keep different readings (a robust fit from far off can end where a
// good reading looks bad and leave it out) or different rows (the start
// cannot be built from a row whose cable geometry the nominal anchors make
// infeasible), so their chi-squares alone do not compare.

#include "solver/calibration/calibrate.h"

namespace cdpr {

// True when other starts are worth their time: the fit failed or was
// refused, its start could not take every row, it left readings out as
// gross errors, or the model-fit test failed. A clean fit of every row
// passes, so clean data costs no extra fit.
bool worth_other_starts(const CalibrationResult& result);

// The fit's chi-square plus threshold_sigma^2 per reading it left out, a
// row refused at the start counting as all its readings left out: the cost
// of a truncated quadratic, under which a gross error costs the same
// wherever it lies, so fits that kept different readings or rows compare.
// (Counting rows first would let a fit of every row win with any
// chi-square: a start that takes a row whose cable is nearly slack can end
// tens of metres off, against the minimum of the other rows.)
double start_score(const CalibrationResult& result, double threshold_sigma);

// True when `candidate` is the better fit of the same samples: a fit beats
// a failure; then a start_score lower by more than 1e-9 relative (equal
// minima keep the incumbent).
bool better_fit(const CalibrationResult& candidate, const CalibrationResult& incumbent, double threshold_sigma);

}  // namespace cdpr
