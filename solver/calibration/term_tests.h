#pragma once
// Which known model term (solver/model/effects.h) a final catenary fit lacks:
// a score (Rao, Lagrange-multiplier) test of each term not in the model,
// evaluated once at the fit, without fitting the term.
//
// With J the whitened (robustly weighted; readings left out as gross errors
// have zero rows) Jacobian of the fit's factors and r their residuals at the
// fit, with the term's parameters added at 0 ("absent"), the term's score is
// u = J_e' r less what the fitted unknowns t (poses, reference forces,
// anchors, offsets, the model's terms) take of it, and its information with
// t profiled out is M = I_ee - I_et I_tt^-1 I_te (I = J'J). Then
//   S = u' M^-1 u ~ chi-square(dim e)
// when the fitted model holds, and S is the chi-square drop a refit with the
// term would give to first order: a likelihood-ratio test for the price of
// one linearisation. The poses are eliminated one by one (the Schur
// structure of the fit), so the cost is linear in the poses.
//
// S is divided by the fit's chi2/dof when that is above 1, so a wrong noise
// level in robot.toml, which inflates every term alike, does not name a
// term. A direction of a term that the fitted unknowns carry (almost) all of
// (its profiled information below 1e-6 of its own) is not tested; a term
// with no other direction is reported as not identifiable on these poses.
// Each remaining term is tested at term_test_alpha / (number of terms
// tested), so the chance that a fit of a correct model names any term is at
// most term_test_alpha.

#include "solver/calibration/calibrate.h"

namespace cdpr {

// Fills result.term_tests and result.term_test_level; a term asked for sets
// result.misfit and is named with its evidence in
// result.calibration.model_warning (after the chi-square test's words, if
// any). Nothing when the fit failed, is rigid, is under-determined, has no
// fitted rows, or options turn the tests off (CalibrationOptions::
// term_test_alpha, misfit_alpha). Runs after the fit; allocates.
void test_missing_terms(const Robot& robot, const CalibrationOptions& options, CalibrationResult& result);

}  // namespace cdpr
