#include "solver/nls/trust_region_strategy.h"

#include <algorithm>

namespace cdpr {

TrustRegionStrategy::TrustRegionStrategy(const TrustRegionOptions& options)
    : options_(options), radius_(options.initial_radius) {}

void TrustRegionStrategy::reset() {
  radius_ = options_.initial_radius;
  nu_ = 2.0;
  step_quality_ = 0.0;
}

bool TrustRegionStrategy::judge_step(double cost, double candidate_cost, double predicted_decrease) {
  step_quality_ = predicted_decrease > 0.0 ? (cost - candidate_cost) / predicted_decrease : 0.0;
  // Written so that a NaN gain ratio (candidate not evaluable) refuses the step.
  if (!(predicted_decrease > 0.0 && step_quality_ > options_.min_relative_decrease)) {
    reject_step();
    return false;
  }
  const double t = 2.0 * step_quality_ - 1.0;
  radius_ = std::min(options_.max_radius, radius_ / std::max(1.0 / 3.0, 1.0 - t * t * t));
  nu_ = 2.0;
  return true;
}

void TrustRegionStrategy::reject_step() {
  radius_ /= nu_;
  nu_ *= 2.0;
}

}  // namespace cdpr
