#pragma once
// SE(3) pose world_T_platform: p_world = world_R_platform * p_platform + position_world.
// Perturbations act on the right (platform frame) for rotation and additively
// on the translation: position += d_p, R = R * Exp(d_theta). Tangent order: (d_p, d_theta).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cdpr {

struct Pose {
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  Eigen::Quaterniond world_R_platform = Eigen::Quaterniond::Identity();

  Eigen::Vector3d transform(const Eigen::Vector3d& p_platform) const {
    return world_R_platform * p_platform + position_world;
  }
};

Eigen::Matrix3d skew(const Eigen::Vector3d& v);
Eigen::Quaterniond so3_exp(const Eigen::Vector3d& rotation_vector);
Eigen::Vector3d so3_log(const Eigen::Quaterniond& q);
// Inverse of the right Jacobian of SO(3): d log(R0^T R Exp(d)) / d d at d = 0 is Jr^-1(log(R0^T R)).
Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& rotation_vector);

// Applies a 6-dim tangent step (d_p, d_theta) to a pose.
void retract(Pose& pose, const double* step);

}  // namespace cdpr
