#pragma once
// A Euclidean variable held near a known value by a diagonal Gaussian prior:
// residual_j = (x_j - x0_j) / sigma_j. The calibration's anchors, offsets and
// model terms as priors of the operation-time problems (the paper's outlook:
// the calibration as priors, the pose unknown). Every sigma > 0.

#include <array>
#include <vector>

#include "solver/nls/factor.h"

namespace cdpr {

class ValuePriorFactor final : public Factor {
 public:
  ValuePriorFactor(Key key, std::vector<double> value, std::vector<double> sigma);

  int residual_dim() const override { return static_cast<int>(value_.size()); }
  std::span<const Key> keys() const override { return keys_; }
  bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                double* cost) const override;

 private:
  std::array<Key, 1> keys_;
  std::vector<double> value_;
  std::vector<double> sigma_;
};

}  // namespace cdpr
