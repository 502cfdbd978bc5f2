#include "solver/fit_comparison.h"

#include <algorithm>

#include "solver/chi_square.h"
#include "solver/effect_pose_factor.h"

namespace cdpr {
namespace {

// Anchor (3) and offset (1) per cable, plus every fitted term's parameters.
int global_parameter_count(const CalibrationResult& fit) {
  int count = 4 * kCableCount;
  for (const FittedEffect& e : fit.effects) count += effect_dimension(e.effect);
  return count;
}

}  // namespace

FitComparison compare_fits(const CalibrationResult& smaller, const CalibrationResult& larger) {
  FitComparison out;
  if (!smaller.ok || !larger.ok) {
    out.why_not = "a fit on all samples failed";
    return out;
  }
  std::vector<int> rejected_smaller = smaller.rejected_samples, rejected_larger = larger.rejected_samples;
  std::sort(rejected_smaller.begin(), rejected_smaller.end());
  std::sort(rejected_larger.begin(), rejected_larger.end());
  if (rejected_smaller != rejected_larger) {
    out.why_not = "the two fits kept different samples";
    return out;
  }
  const int parameters_smaller = global_parameter_count(smaller), parameters_larger = global_parameter_count(larger);
  out.added_parameters = parameters_larger - parameters_smaller;
  if (out.added_parameters <= 0) {
    out.why_not = "the larger model adds no parameter";
    return out;
  }
  // Per pose: encoder, height and force residuals plus the 6 of the pose
  // prior, less the pose's own 8 unknowns (pose 6, reference force 2).
  const int per_pose = EffectPoseFactor::kResidualDim + 6 - 8;
  const int dof = per_pose * larger.calibration.samples - parameters_larger;
  const double chi2_larger = 2.0 * larger.solver.final_cost;
  out.chi2_drop = 2.0 * (smaller.solver.final_cost - larger.solver.final_cost);
  out.scale = dof > 0 ? std::max(1.0, chi2_larger / dof) : 1.0;
  out.p_value = chi_square_upper_tail(out.chi2_drop / out.scale, out.added_parameters);
  out.comparable = true;
  return out;
}

}  // namespace cdpr
