#pragma once
// The massless straight-cable model the paper compares against (Sec. VI-A):
// encoder i reads |b_i - a_i| + l0_i. Variables: PoseKey(k), AnchorKey(i), OffsetKey(i).

#include <array>

#include <Eigen/Core>

#include "solver/nls/factor.h"
#include "solver/nls/loss.h"

namespace cdpr {

class RigidEncoderFactor final : public Factor {
 public:
  RigidEncoderFactor(int pose_index, int cable, const Eigen::Vector3d& attachment_platform, double encoder_m,
                     double sigma_encoder_m, Loss loss);

  int residual_dim() const override { return 1; }
  std::span<const Key> keys() const override { return keys_; }
  bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                double* cost) const override;

 private:
  std::array<Key, 3> keys_;
  Eigen::Vector3d attachment_platform_;
  double encoder_m_;
  double sigma_encoder_m_;
  Loss loss_;
};

}  // namespace cdpr
