#pragma once
// Chi-square and normal tail probabilities for the model-discrepancy
// workflow's tests (solver/diagnosis/diagnosis.h, solver/diagnosis/fit_comparison.h).

namespace cdpr {

// P(Z > z) for a standard normal Z.
double normal_upper_tail(double z);
// P(X > x) for X ~ chi-square(k): exact for k <= 30 (the small counts of a
// likelihood-ratio test, where Wilson-Hilferty is off by tens of percent in
// the far tail), Wilson-Hilferty above.
double chi_square_upper_tail(double x, int k);
// P(X > x) for X ~ a chi-square(nu) whose mean a nu and variance 2 a^2 nu
// are `mean` and `variance` (Satterthwaite's match for a sum of squares
// whose terms are not independent); Wilson-Hilferty, nu need not be whole.
// A variance <= 0 is taken as 2 mean, a plain chi-square(mean).
double scaled_chi_square_upper_tail(double x, double mean, double variance);

}  // namespace cdpr
