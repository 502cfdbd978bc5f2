#include "solver/nls/pose.h"

#include <cmath>

namespace cdpr {
namespace {
// Below this angle [rad] the closed forms lose precision (1 - cos, sin/theta)
// and their Taylor series are exact to double precision.
constexpr double kSmallAngle = 1e-5;
}  // namespace

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Quaterniond so3_exp(const Eigen::Vector3d& rotation_vector) {
  const double theta = rotation_vector.norm();
  double w, s;  // q = (w, s * rotation_vector)
  if (theta < kSmallAngle) {
    const double t2 = theta * theta;
    w = 1.0 - t2 / 8.0;
    s = 0.5 - t2 / 48.0;
  } else {
    w = std::cos(0.5 * theta);
    s = std::sin(0.5 * theta) / theta;
  }
  // Written as two pairs (x, y) and (z, w), the halves Eigen's quaternion
  // product loads: (z, w) written one entry at a time made that load wait
  // for both stores to reach the cache, as the CPU cannot forward it from them.
  Eigen::Quaterniond q;
  q.coeffs().head<2>() = s * rotation_vector.head<2>();
  q.coeffs().tail<2>() = Eigen::Vector2d(s * rotation_vector.z(), w);
  return q;
}

Eigen::Vector3d so3_log(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  // q and -q are the same rotation; w >= 0 picks the angle in [0, pi].
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double n = v.norm();
  // atan2 stays accurate near pi, where w -> 0 and acos(w) would be ill-conditioned.
  double factor;  // rotation_vector = factor * v
  if (n < kSmallAngle) {
    const double w = q.w();
    factor = 2.0 / w * (1.0 - n * n / (3.0 * w * w));
  } else {
    factor = 2.0 * std::atan2(n, q.w()) / n;
  }
  return factor * v;
}

Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& rotation_vector) {
  // Jr^-1(phi) = I + phi^/2 + (1/theta^2 - (1 + cos theta) / (2 theta sin theta)) phi^ phi^.
  const double theta = rotation_vector.norm();
  const Eigen::Matrix3d phi = skew(rotation_vector);
  double c;
  if (theta < kSmallAngle) {
    c = 1.0 / 12.0 + theta * theta / 720.0;
  } else {
    c = 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  }
  return Eigen::Matrix3d::Identity() + 0.5 * phi + c * phi * phi;
}

void retract(Pose& pose, const double* step) {
  pose.position_world += Eigen::Vector3d(step[0], step[1], step[2]);
  pose.world_R_platform = (pose.world_R_platform * so3_exp(Eigen::Vector3d(step[3], step[4], step[5]))).normalized();
}

}  // namespace cdpr
