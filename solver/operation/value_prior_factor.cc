#include "solver/operation/value_prior_factor.h"

#include <cstdlib>
#include <utility>

namespace cdpr {

ValuePriorFactor::ValuePriorFactor(Key key, std::vector<double> value, std::vector<double> sigma)
    : keys_{key}, value_(std::move(value)), sigma_(std::move(sigma)) {
  if (value_.empty() || value_.size() != sigma_.size()) std::abort();
  for (double s : sigma_) {
    if (!(s > 0.0)) std::abort();
  }
}

bool ValuePriorFactor::evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                                double* cost) const {
  const int n = residual_dim();
  *cost = 0.0;
  for (int j = 0; j < n; ++j) {
    residual[j] = (parameters[0][j] - value_[j]) / sigma_[j];
    *cost += 0.5 * residual[j] * residual[j];
  }
  if (jacobians && jacobians[0]) {
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) jacobians[0][r * n + c] = r == c ? 1.0 / sigma_[r] : 0.0;
    }
  }
  return true;
}

}  // namespace cdpr
