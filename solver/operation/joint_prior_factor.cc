#include "solver/operation/joint_prior_factor.h"

#include <cstdlib>
#include <utility>

#include <Eigen/Cholesky>

namespace cdpr {

JointPriorFactor::JointPriorFactor(std::vector<Key> keys, std::vector<int> sizes, const Eigen::VectorXd& value,
                                   const Eigen::MatrixXd& covariance)
    : keys_(std::move(keys)), sizes_(std::move(sizes)), value_(value) {
  int total = 0;
  for (int size : sizes_) {
    offsets_.push_back(total);
    total += size;
  }
  if (keys_.size() != sizes_.size() || total != value_.size() || covariance.rows() != total ||
      covariance.cols() != total) {
    std::abort();
  }
  // Sigma = L L^T  =>  Sigma^-1 = L^-T L^-1, so W = L^-1.
  const Eigen::LLT<Eigen::MatrixXd> llt(covariance);
  if (llt.info() != Eigen::Success) std::abort();
  whitening_ = llt.matrixL().solve(Eigen::MatrixXd::Identity(total, total));
}

bool JointPriorFactor::evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                                double* cost) const {
  const int n = residual_dim();
  Eigen::Map<Eigen::VectorXd> r(residual, n);
  r.setZero();
  for (std::size_t k = 0; k < keys_.size(); ++k) {
    const Eigen::Map<const Eigen::VectorXd> x(parameters[k], sizes_[k]);
    r.noalias() += whitening_.middleCols(offsets_[k], sizes_[k]) * (x - value_.segment(offsets_[k], sizes_[k]));
  }
  *cost = 0.5 * r.squaredNorm();
  if (jacobians) {
    for (std::size_t k = 0; k < keys_.size(); ++k) {
      if (!jacobians[k]) continue;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(jacobians[k], n, sizes_[k]);
      J = whitening_.middleCols(offsets_[k], sizes_[k]);
    }
  }
  return true;
}

}  // namespace cdpr
