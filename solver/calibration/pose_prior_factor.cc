#include "solver/calibration/pose_prior_factor.h"

#include "solver/nls/factor_support.h"

namespace cdpr {
namespace {
constexpr std::array<int, 1> kPosePriorBlockDims = {6};
}

PosePriorFactor::PosePriorFactor(int pose_index, const Pose& measured, double sigma_position_m,
                                 double sigma_orientation_rad, Loss loss)
    : keys_{PoseKey(pose_index)},
      measured_(measured),
      sigma_position_m_(sigma_position_m),
      sigma_orientation_rad_(sigma_orientation_rad),
      loss_(loss) {}

bool PosePriorFactor::evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                               double* cost) const {
  const Pose pose = pose_from_parameters(parameters[0]);
  const Eigen::Vector3d dp = (pose.position_world - measured_.position_world) / sigma_position_m_;
  const Eigen::Vector3d rotation_error = so3_log(measured_.world_R_platform.conjugate() * pose.world_R_platform);
  Eigen::Map<Eigen::Matrix<double, 6, 1>> r(residual);
  r.head<3>() = dp;
  r.tail<3>() = rotation_error / sigma_orientation_rad_;
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.topLeftCorner<3, 3>().diagonal().setConstant(1.0 / sigma_position_m_);
    J.bottomRightCorner<3, 3>() = so3_right_jacobian_inverse(rotation_error) / sigma_orientation_rad_;
  }
  *cost = apply_loss(loss_, 6, residual, jacobians, kPosePriorBlockDims);
  return true;
}

}  // namespace cdpr
