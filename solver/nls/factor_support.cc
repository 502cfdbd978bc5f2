#include "solver/nls/factor_support.h"

namespace cdpr {

Pose pose_from_parameters(const double* ambient) {
  Pose pose;
  pose.position_world = Eigen::Vector3d(ambient[0], ambient[1], ambient[2]);
  pose.world_R_platform = Eigen::Quaterniond(ambient[3], ambient[4], ambient[5], ambient[6]);
  return pose;
}

namespace {

// Cost of row j under the loss; scales the row and its Jacobian rows.
double robustify_row(const Loss& loss, int j, double* residual, double* const* jacobians,
                     std::span<const int> block_dims) {
  // Where the loss is quadratic (on clean data nearly every row) the row
  // stays as it is and costs what cost() would give, bit for bit.
  if (loss.quadratic_at(residual[j])) return 0.5 * residual[j] * residual[j];
  const double cost = loss.cost(residual[j]);
  const double scale = loss.scale(residual[j]);
  if (scale == 1.0) return cost;
  residual[j] *= scale;
  if (jacobians == nullptr) return cost;
  for (std::size_t b = 0; b < block_dims.size(); ++b) {
    if (jacobians[b] == nullptr) continue;
    double* row = jacobians[b] + j * block_dims[b];
    for (int c = 0; c < block_dims[b]; ++c) row[c] *= scale;
  }
  return cost;
}

}  // namespace

double apply_loss(const Loss& loss, int residual_dim, double* residual, double* const* jacobians,
                  std::span<const int> block_dims) {
  double cost = 0.0;
  if (loss.least_squares()) {
    // What robustify_row gives each row then, without asking the loss row by row.
    for (int j = 0; j < residual_dim; ++j) cost += 0.5 * residual[j] * residual[j];
    return cost;
  }
  for (int j = 0; j < residual_dim; ++j) cost += robustify_row(loss, j, residual, jacobians, block_dims);
  return cost;
}

double apply_loss_to_rows(const Loss& loss, std::span<const int> robust_rows, int residual_dim, double* residual,
                          double* const* jacobians, std::span<const int> block_dims) {
  double cost = 0.0;
  for (int j = 0; j < residual_dim; ++j) cost += 0.5 * residual[j] * residual[j];
  for (int j : robust_rows) {
    // A quadratic row would add robustify_row's 0.5 r^2 less the same 0.5 r^2: +0.
    if (loss.quadratic_at(residual[j])) continue;
    const double squared = 0.5 * residual[j] * residual[j];
    cost += robustify_row(loss, j, residual, jacobians, block_dims) - squared;
  }
  return cost;
}

void zero_rows(std::span<const int> rows, double* residual, double* const* jacobians, std::span<const int> block_dims) {
  for (int j : rows) {
    residual[j] = 0.0;
    if (jacobians == nullptr) continue;
    for (std::size_t b = 0; b < block_dims.size(); ++b) {
      if (jacobians[b] == nullptr) continue;
      double* row = jacobians[b] + j * block_dims[b];
      for (int c = 0; c < block_dims[b]; ++c) row[c] = 0.0;
    }
  }
}

}  // namespace cdpr
