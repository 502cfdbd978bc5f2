#include "solver/diagnosis/fit_comparison.h"

#include <algorithm>
#include <limits>
#include <vector>

#include "solver/calibration/chi_square.h"
#include "solver/calibration/effect_pose_factor.h"

namespace cdpr {
namespace {

// Anchor (3) and offset (1) per cable, plus every fitted term's parameters.
int global_parameter_count(const CalibrationResult& fit) {
  int count = 4 * kCableCount;
  for (const FittedEffect& e : fit.effects) count += effect_dimension(e.effect);
  return count;
}

// Whether both fits kept the same samples (their chi2 sum the same data).
bool same_samples(const CalibrationResult& a, const CalibrationResult& b) {
  std::vector<int> rejected_a = a.rejected_samples, rejected_b = b.rejected_samples;
  std::sort(rejected_a.begin(), rejected_a.end());
  std::sort(rejected_b.begin(), rejected_b.end());
  return rejected_a == rejected_b;
}

}  // namespace

FitComparison compare_fits(const CalibrationResult& smaller, const CalibrationResult& larger) {
  FitComparison out;
  if (!smaller.ok || !larger.ok) {
    out.why_not = "a fit on all samples failed";
    return out;
  }
  if (!same_samples(smaller, larger)) {
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

double akaike_gain(const CalibrationResult& from, const CalibrationResult& to) {
  if (!from.ok || !to.ok || !same_samples(from, to)) return -std::numeric_limits<double>::infinity();
  return 2.0 * (from.solver.final_cost - to.solver.final_cost) -
         2.0 * (global_parameter_count(to) - global_parameter_count(from));
}

}  // namespace cdpr
