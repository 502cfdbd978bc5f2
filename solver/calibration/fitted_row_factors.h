#pragma once
// A final fit's row evaluated where the fit ended: its pose prior and its
// reading factor (EffectPoseFactor) at the row's fitted pose and reference
// force, every global at the fit. The tests run after a fit that look at
// one row at a time (the score test of missing terms where the fit kept no
// linearisation of its own, the studentised test of the kept readings)
// linearise the rows this way.

#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/model/effects.h"
#include "solver/nls/loss.h"

namespace cdpr {

// Where evaluate_fitted_row() writes: the prior's 6 residuals and its pose
// block's Jacobian, the reading factor's residuals and Jacobians (one per
// keys() block, null where not wanted).
struct FittedRowOutput {
  double* prior_residual;
  double* const* prior_jacobians;
  double* residual;
  double* const* jacobians;
};

// Sets `pose` (7: position, then quaternion w, x, y, z) and `force` (2) to
// `row`'s fitted values and evaluates row `index`'s pose prior and reading
// factor at `parameters` (EffectPoseFactor's keys() order: `pose`, `force`,
// anchors, offsets, `effects`' values). False when either cannot be evaluated.
bool evaluate_fitted_row(const Robot& robot, const FittedRow& row, int index, double height_sigma_m, const Loss& loss,
                         const std::vector<Effect>& effects, double* pose, double* force,
                         const double* const* parameters, const FittedRowOutput& out);

}  // namespace cdpr
