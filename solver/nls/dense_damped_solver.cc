#include "solver/nls/dense_damped_solver.h"

#include <cstdio>

namespace cdpr {

const char* to_string(DenseDampedStop stop) {
  switch (stop) {
    case DenseDampedStop::kResidualTolerance: return "residual tolerance reached";
    case DenseDampedStop::kSmallGain: return "the decrease fell below the tolerance";
    case DenseDampedStop::kMaxTrials: return "out of trial steps";
    case DenseDampedStop::kTrustRegionCollapsed: return "trust region collapsed: no step decreases the cost";
    case DenseDampedStop::kNotEvaluable: return "the start cannot be evaluated";
    case DenseDampedStop::kJacobianNotEvaluable: return "the Jacobian cannot be evaluated next to an accepted point";
  }
  return "unknown";
}

std::string DenseDampedSummary::message() const {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, "%s; chi2 %.6e -> %.6e in %d trials (%d accepted)", to_string(stop),
                initial_chi2, final_chi2, trials, accepted);
  return buffer;
}

}  // namespace cdpr
