#include "solver/calibration/start_selection.h"

#include <cmath>

namespace cdpr {

bool worth_other_starts(const CalibrationResult& result) {
  return !result.ok || !result.rejected_samples.empty() || !result.gross_errors.empty() || result.misfit;
}

double start_score(const CalibrationResult& result, double threshold_sigma) {
  // A row refused at the start leaves out its encoders and its load cell.
  const double left_out = static_cast<double>(result.gross_errors.size()) +
                          static_cast<double>((kCableCount + 1) * result.rejected_samples.size());
  return result.chi_square + threshold_sigma * threshold_sigma * left_out;
}

bool better_fit(const CalibrationResult& candidate, const CalibrationResult& incumbent, double threshold_sigma) {
  if (candidate.ok != incumbent.ok) return candidate.ok;
  if (!candidate.ok) return false;
  const double a = start_score(candidate, threshold_sigma), b = start_score(incumbent, threshold_sigma);
  return a < b - 1e-9 * std::abs(b);
}

}  // namespace cdpr
