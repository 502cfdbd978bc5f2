#pragma once
// Chi-square and normal tail probabilities for the model-discrepancy
// workflow's tests (solver/diagnosis.h, solver/fit_comparison.h).

namespace cdpr {

// P(Z > z) for a standard normal Z.
double normal_upper_tail(double z);
// P(X > x) for X ~ chi-square(k): exact for k <= 30 (the small counts of a
// likelihood-ratio test, where Wilson-Hilferty is off by tens of percent in
// the far tail), Wilson-Hilferty above.
double chi_square_upper_tail(double x, int k);

}  // namespace cdpr
