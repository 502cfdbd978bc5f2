#pragma once
// Likelihood-ratio test between two nested fits on the same samples (solver/
// diagnosis.h): the larger model's drop in chi-square, 2 (cost_smaller -
// cost_larger), against chi-square(k) with k the parameters it adds. It is
// the most powerful test of a term when the data hold it (about twice the z
// of a test of held-out chi-square drops, whose per-pose noise is twice the
// signal's), but it needs the sensor sigmas to be right: the drop is divided
// by the larger model's chi2 / dof when that exceeds 1 (an F-test in spirit),
// so noise larger than robot.toml says makes the test stricter, not looser.

#include <string>

#include "solver/calibration/calibrate.h"

namespace cdpr {

struct FitComparison {
  bool comparable = false;
  std::string why_not;      // when !comparable
  double chi2_drop = 0.0;   // 2 (cost_smaller - cost_larger)
  double scale = 1.0;       // max(1, chi2 / dof of the larger fit)
  int added_parameters = 0;
  double p_value = 1.0;     // P(chi-square(added) > drop / scale)
};

// Both fits must be ok calibrate() results without a robust loss; they are
// comparable when they kept the same samples and `larger` has more parameters.
FitComparison compare_fits(const CalibrationResult& smaller, const CalibrationResult& larger);

// Akaike's criterion from `from` to `to`, two ok fits of any models on the
// same samples: the drop in chi2, 2 (cost_from - cost_to), less 2 per
// parameter `to` has beyond `from` (negative when it has fewer). Positive:
// `to` is the better model by the expected Kullback-Leibler distance to the
// truth; it needs no nesting, so it compares a pair of terms with a third.
// Minus infinity when a fit failed or they kept different samples.
double akaike_gain(const CalibrationResult& from, const CalibrationResult& to);

}  // namespace cdpr
