#include "solver/factor_support.h"

namespace cdpr {

Pose pose_from_parameters(const double* ambient) {
  Pose pose;
  pose.position_world = Eigen::Vector3d(ambient[0], ambient[1], ambient[2]);
  pose.world_R_platform = Eigen::Quaterniond(ambient[3], ambient[4], ambient[5], ambient[6]);
  return pose;
}

double apply_loss(const Loss& loss, int residual_dim, double* residual, double* const* jacobians,
                  std::span<const int> block_dims) {
  double cost = 0.0;
  for (int j = 0; j < residual_dim; ++j) {
    cost += loss.cost(residual[j]);
    const double scale = loss.scale(residual[j]);
    if (scale == 1.0) continue;
    residual[j] *= scale;
    if (jacobians == nullptr) continue;
    for (std::size_t b = 0; b < block_dims.size(); ++b) {
      if (jacobians[b] == nullptr) continue;
      double* row = jacobians[b] + j * block_dims[b];
      for (int c = 0; c < block_dims[b]; ++c) row[c] *= scale;
    }
  }
  return cost;
}

}  // namespace cdpr
