#pragma once
// Small factors for the LM tests, on SizedFactor: an exponential curve point,
// SE(3) prior and relative-pose factors, a cable-like range factor, the four
// ranges of a pose stacked, and a linear-Gaussian factor. Their Jacobians
// are checked numerically in lm_test_factors_test.cc.

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "solver/nls/pose.h"
#include "solver/nls/sized_factor.h"

namespace cdpr::test {

inline Pose pose_at(const double* ambient) { return pose_from_parameters(ambient); }

// y = exp(m t + c) at one sample; variable: (m, c).
class ExpCurveFactor final : public SizedFactor<1, 2> {
 public:
  ExpCurveFactor(Key key, double t, double y, Loss loss = {}) : SizedFactor({key}, loss), t_(t), y_(y) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    const double e = std::exp(x[0][0] * t_ + x[0][1]);
    r[0] = e - y_;
    if (auto J = jacobian<0>(j)) *J << e * t_, e;
    return true;
  }
  double t_, y_;
};

// Straight line y = m t + c at one sample, whitened by sigma; variable (m, c).
class LineFactor final : public SizedFactor<1, 2> {
 public:
  LineFactor(Key key, double t, double y, double sigma, Loss loss)
      : SizedFactor({key}, loss), t_(t), y_(y), sigma_(sigma) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    r[0] = (x[0][0] * t_ + x[0][1] - y_) / sigma_;
    if (auto J = jacobian<0>(j)) *J << t_ / sigma_, 1.0 / sigma_;
    return true;
  }
  double t_, y_, sigma_;
};

// r = (log(x) - log(target)) / sigma; cannot be evaluated for x <= 0.
// Counts the refusals so a test can see the region was visited.
class LogFactor final : public SizedFactor<1, 1> {
 public:
  LogFactor(Key key, double target, double sigma, int* refusals)
      : SizedFactor({key}, Loss{}), log_target_(std::log(target)), sigma_(sigma), refusals_(refusals) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    if (x[0][0] <= 0.0) {
      ++*refusals_;
      return false;
    }
    r[0] = (std::log(x[0][0]) - log_target_) / sigma_;
    if (auto J = jacobian<0>(j)) (*J)(0, 0) = 1.0 / (x[0][0] * sigma_);
    return true;
  }
  double log_target_, sigma_;
  int* refusals_;
};

// Measured pose: [(p - p_meas) / sigma_p; log(R_meas^T R) / sigma_r].
class SE3PriorFactor final : public SizedFactor<6, 6> {
 public:
  SE3PriorFactor(Key key, const Pose& measured, double sigma_p, double sigma_r, Loss loss = {})
      : SizedFactor({key}, loss), measured_(measured), sigma_p_(sigma_p), sigma_r_(sigma_r) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    const Pose pose = pose_at(x[0]);
    const Eigen::Vector3d phi = so3_log(measured_.world_R_platform.conjugate() * pose.world_R_platform);
    Residuals residual(r);
    residual << (pose.position_world - measured_.position_world) / sigma_p_, phi / sigma_r_;
    if (auto J = jacobian<0>(j)) {
      J->setZero();
      J->topLeftCorner<3, 3>().diagonal().setConstant(1.0 / sigma_p_);
      J->bottomRightCorner<3, 3>() = so3_right_jacobian_inverse(phi) / sigma_r_;
    }
    return true;
  }
  Pose measured_;
  double sigma_p_, sigma_r_;
};

// Relative pose a_T_b measured: [R_a^T (p_b - p_a) - t_meas; log(R_meas^T R_a^T R_b)] / sigma.
class SE3BetweenFactor final : public SizedFactor<6, 6, 6> {
 public:
  SE3BetweenFactor(Key a, Key b, const Pose& a_T_b, double sigma_p, double sigma_r)
      : SizedFactor({a, b}, Loss{}), measured_(a_T_b), sigma_p_(sigma_p), sigma_r_(sigma_r) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    const Pose a = pose_at(x[0]), b = pose_at(x[1]);
    const Eigen::Matrix3d Ra = a.world_R_platform.toRotationMatrix();
    const Eigen::Matrix3d Rb = b.world_R_platform.toRotationMatrix();
    const Eigen::Vector3d t = Ra.transpose() * (b.position_world - a.position_world);
    const Eigen::Vector3d phi =
        so3_log(measured_.world_R_platform.conjugate() * a.world_R_platform.conjugate() * b.world_R_platform);
    Residuals residual(r);
    residual << (t - measured_.position_world) / sigma_p_, phi / sigma_r_;
    const Eigen::Matrix3d jr_inv = so3_right_jacobian_inverse(phi);
    if (auto J = jacobian<0>(j)) {
      J->topLeftCorner<3, 3>() = -Ra.transpose() / sigma_p_;
      J->topRightCorner<3, 3>() = skew(t) / sigma_p_;
      J->bottomLeftCorner<3, 3>().setZero();
      J->bottomRightCorner<3, 3>() = -jr_inv * Rb.transpose() * Ra / sigma_r_;
    }
    if (auto J = jacobian<1>(j)) {
      J->topLeftCorner<3, 3>() = Ra.transpose() / sigma_p_;
      J->topRightCorner<3, 3>().setZero();
      J->bottomLeftCorner<3, 3>().setZero();
      J->bottomRightCorner<3, 3>() = jr_inv / sigma_r_;
    }
    return true;
  }
  Pose measured_;
  double sigma_p_, sigma_r_;
};

// A straight cable: encoder = |anchor - world_T_platform * attachment| + offset.
// Variables: pose (6), anchor (3), offset (1).
class RangeFactor final : public SizedFactor<1, 6, 3, 1> {
 public:
  RangeFactor(Key pose, Key anchor, Key offset, const Eigen::Vector3d& attachment_platform, double encoder_m,
              double sigma_m, Loss loss = {})
      : SizedFactor({pose, anchor, offset}, loss),
        attachment_platform_(attachment_platform),
        encoder_m_(encoder_m),
        sigma_m_(sigma_m) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    const Pose pose = pose_at(x[0]);
    const Eigen::Map<const Eigen::Vector3d> anchor(x[1]);
    const Eigen::Vector3d d = pose.transform(attachment_platform_) - anchor;
    const double length = d.norm();
    if (length < 1e-9) return false;
    r[0] = (length + x[2][0] - encoder_m_) / sigma_m_;
    const Eigen::RowVector3d u = d.transpose() / (length * sigma_m_);
    if (auto J = jacobian<0>(j)) {
      J->leftCols<3>() = u;
      J->rightCols<3>() = -u * pose.world_R_platform.toRotationMatrix() * skew(attachment_platform_);
    }
    if (auto J = jacobian<1>(j)) *J = -u;
    if (auto J = jacobian<2>(j)) (*J)(0, 0) = 1.0 / sigma_m_;
    return true;
  }
  Eigen::Vector3d attachment_platform_;
  double encoder_m_, sigma_m_;
};

// The four ranges of one pose in one factor, as StaticPoseFactor stacks a
// pose's cables, each cable read kReadings times: rows [i R, (i + 1) R) are
// cable i's, so anchor i and offset i reach those rows alone, which the
// factor declares (Factor::jacobian_rows). Variables: pose (6), anchors
// 0..3 (3 each), offsets 0..3 (1 each).
template <int kReadings>
class StackedRangesFactor final : public SizedFactor<4 * kReadings, 6, 3, 3, 3, 3, 1, 1, 1, 1> {
  using Base = SizedFactor<4 * kReadings, 6, 3, 3, 3, 3, 1, 1, 1, 1>;
  static constexpr int kRows = 4 * kReadings;

 public:
  // encoders_m[i * kReadings + r]: reading r of cable i.
  StackedRangesFactor(int pose, const std::array<Eigen::Vector3d, 4>& attachments_platform,
                      const std::array<double, kRows>& encoders_m, double sigma_m, Loss loss = {})
      : Base({PoseKey(pose), AnchorKey(0), AnchorKey(1), AnchorKey(2), AnchorKey(3), OffsetKey(0), OffsetKey(1),
              OffsetKey(2), OffsetKey(3)},
             loss),
        attachments_platform_(attachments_platform),
        encoders_m_(encoders_m),
        sigma_m_(sigma_m) {}

  RowRange jacobian_rows(int k) const override {
    if (k == 0) return {0, kRows};
    const int cable = (k - 1) % 4;
    return {cable * kReadings, (cable + 1) * kReadings};
  }

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    const Pose pose = pose_at(x[0]);
    const Eigen::Matrix3d rotation = pose.world_R_platform.toRotationMatrix();
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d d = pose.transform(attachments_platform_[i]) - Eigen::Map<const Eigen::Vector3d>(x[1 + i]);
      const double length = d.norm();
      if (length < 1e-9) return false;
      const Eigen::RowVector3d u = d.transpose() / (length * sigma_m_);
      const Eigen::RowVector3d turn = -u * rotation * skew(attachments_platform_[i]);
      double* anchor = j ? j[1 + i] : nullptr;
      double* offset = j ? j[5 + i] : nullptr;
      if (anchor) std::fill(anchor, anchor + 3 * kRows, 0.0);
      if (offset) std::fill(offset, offset + kRows, 0.0);
      for (int row = i * kReadings; row < (i + 1) * kReadings; ++row) {
        r[row] = (length + x[5 + i][0] - encoders_m_[row]) / sigma_m_;
        if (j && j[0]) {
          for (int c = 0; c < 3; ++c) {
            j[0][row * 6 + c] = u(c);
            j[0][row * 6 + 3 + c] = turn(c);
          }
        }
        if (anchor) for (int c = 0; c < 3; ++c) anchor[3 * row + c] = -u(c);
        if (offset) offset[row] = 1.0 / sigma_m_;
      }
    }
    return true;
  }
  std::array<Eigen::Vector3d, 4> attachments_platform_;
  std::array<double, kRows> encoders_m_;
  double sigma_m_;
};

// Linear-Gaussian: r = (A_1 x_1 + A_2 x_2 - b) / sigma, x_i 2-vectors.
class LinearFactor final : public SizedFactor<2, 2, 2> {
 public:
  LinearFactor(Key k1, Key k2, const Eigen::Matrix2d& a1, const Eigen::Matrix2d& a2, const Eigen::Vector2d& b,
               double sigma)
      : SizedFactor({k1, k2}, Loss{}), a1_(a1 / sigma), a2_(a2 / sigma), b_(b / sigma) {}

 private:
  bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
    Residuals residual(r);
    residual = a1_ * Eigen::Map<const Eigen::Vector2d>(x[0]) + a2_ * Eigen::Map<const Eigen::Vector2d>(x[1]) - b_;
    if (auto J = jacobian<0>(j)) *J = a1_;
    if (auto J = jacobian<1>(j)) *J = a2_;
    return true;
  }
  Eigen::Matrix2d a1_, a2_;
  Eigen::Vector2d b_;
};

}  // namespace cdpr::test
