#pragma once
// The test that a final fit's model explains its data, applied by calibrate().

#include "solver/calibration/calibrate.h"

namespace cdpr {

// The model-fit test of a final fit: chi-square against its degrees of
// freedom, and a problem with fewer redundant rows than global unknowns
// (3 poses of 4 cables, say) is under-determined whatever its chi-square.
// A fit the solver left at its iteration limit is not at a minimum and is
// flagged whatever its chi-square. A misfit scales the sigmas up by
// sqrt(chi2 / dof), never down; one of more than 1e4 is said to be a fit
// that did not reach the readings, not a missing model term.
void assess_model_fit(CalibrationResult& result, const CalibrationOptions& options);

}  // namespace cdpr
