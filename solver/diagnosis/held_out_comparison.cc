#include "solver/diagnosis/held_out_comparison.h"

#include <cmath>
#include <unordered_map>
#include <vector>

namespace cdpr {

HeldOutComparison compare_held_out(const HeldOutEvaluation& current, const HeldOutEvaluation& candidate) {
  std::unordered_map<int, double> candidate_chi2;
  for (const HeldOutPose& pose : candidate.poses) candidate_chi2[pose.sample.id] = pose.chi2;
  std::vector<double> drops;
  for (const HeldOutPose& pose : current.poses) {
    const auto match = candidate_chi2.find(pose.sample.id);
    if (match != candidate_chi2.end()) drops.push_back(pose.chi2 - match->second);
  }
  HeldOutComparison out;
  out.paired_poses = static_cast<int>(drops.size());
  for (double d : drops) out.drop += d;
  const double n = static_cast<double>(drops.size());
  if (drops.size() < 3) return out;
  const double mean = out.drop / n;
  double square = 0.0;
  for (double d : drops) square += (d - mean) * (d - mean);
  const double standard_error = std::sqrt(square / (n - 1.0) / n);
  out.t_statistic = standard_error > 0.0 ? mean / standard_error : 0.0;
  return out;
}

}  // namespace cdpr
