#include "solver/calibration/start_selection.h"

#include <cmath>

namespace cdpr {

bool worth_other_starts(const CalibrationResult& result) {
  return !result.ok || !result.rejected_samples.empty() || !result.gross_errors.empty() || result.misfit;
}

double start_score(const CalibrationResult& result, double threshold_sigma) {
  return result.chi_square + threshold_sigma * threshold_sigma * static_cast<double>(result.gross_errors.size());
}

bool better_fit(const CalibrationResult& candidate, const CalibrationResult& incumbent, double threshold_sigma) {
  if (candidate.ok != incumbent.ok) return candidate.ok;
  if (!candidate.ok) return false;
  if (candidate.calibration.samples != incumbent.calibration.samples) {
    return candidate.calibration.samples > incumbent.calibration.samples;
  }
  const double a = start_score(candidate, threshold_sigma), b = start_score(incumbent, threshold_sigma);
  return a < b - 1e-9 * std::abs(b);
}

}  // namespace cdpr
