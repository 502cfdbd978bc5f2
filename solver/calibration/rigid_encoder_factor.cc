#include "solver/calibration/rigid_encoder_factor.h"

#include "solver/nls/factor_support.h"

namespace cdpr {
namespace {
constexpr std::array<int, 3> kRigidEncoderBlockDims = {6, 3, 1};
}

RigidEncoderFactor::RigidEncoderFactor(int pose_index, int cable, const Eigen::Vector3d& attachment_platform,
                                       double encoder_m, double sigma_encoder_m, Loss loss)
    : keys_{PoseKey(pose_index), AnchorKey(cable), OffsetKey(cable)},
      attachment_platform_(attachment_platform),
      encoder_m_(encoder_m),
      sigma_encoder_m_(sigma_encoder_m),
      loss_(loss) {}

bool RigidEncoderFactor::evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                                  double* cost) const {
  const Pose pose = pose_from_parameters(parameters[0]);
  const Eigen::Vector3d anchor(parameters[1][0], parameters[1][1], parameters[1][2]);
  const Eigen::Vector3d lever_world = pose.world_R_platform * attachment_platform_;
  const Eigen::Vector3d chord = pose.position_world + lever_world - anchor;
  const double length = chord.norm();
  if (!(length > 0.0)) return false;
  residual[0] = (length + parameters[2][0] - encoder_m_) / sigma_encoder_m_;
  if (jacobians) {
    const Eigen::Vector3d u = chord / (length * sigma_encoder_m_);
    if (jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 1, 6>> J(jacobians[0]);
      J.head<3>() = u.transpose();
      // d(R b) / d theta = -R [b]x for the right perturbation.
      J.tail<3>() = -u.transpose() * pose.world_R_platform.toRotationMatrix() * skew(attachment_platform_);
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, 1, 3>> J(jacobians[1]);
      J = -u.transpose();
    }
    if (jacobians[2]) jacobians[2][0] = 1.0 / sigma_encoder_m_;
  }
  *cost = apply_loss(loss_, 1, residual, jacobians, kRigidEncoderBlockDims);
  return true;
}

}  // namespace cdpr
