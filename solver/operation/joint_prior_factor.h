#pragma once
// Euclidean variables held near known values by a Gaussian prior with a full
// covariance: residual = W (x - x0), W^T W = Sigma^-1. The calibration's
// anchors and offsets with the correlations of their fit: along a cable an
// anchor error and an offset error cancel in the length the encoders see,
// which per-variable sigmas cannot say.

#include <vector>

#include <Eigen/Core>

#include "solver/nls/factor.h"

namespace cdpr {

class JointPriorFactor final : public Factor {
 public:
  // `keys` of the given tangent sizes, in the order of `value` and
  // `covariance`'s rows; covariance symmetric positive definite (aborts
  // otherwise: a broken invariant of the caller).
  JointPriorFactor(std::vector<Key> keys, std::vector<int> sizes, const Eigen::VectorXd& value,
                   const Eigen::MatrixXd& covariance);

  int residual_dim() const override { return static_cast<int>(value_.size()); }
  std::span<const Key> keys() const override { return keys_; }
  bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                double* cost) const override;

 private:
  std::vector<Key> keys_;
  std::vector<int> sizes_, offsets_;
  Eigen::VectorXd value_;
  Eigen::MatrixXd whitening_;  // W
};

}  // namespace cdpr
