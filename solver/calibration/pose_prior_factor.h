#pragma once
// Pose prior (paper Sec. IV-C 4): the measured platform pose, weighted by the
// localisation noise. Residual: [(p - p_meas) / sigma_p; log(R_meas^T R) / sigma_r].

#include <array>

#include "solver/nls/factor.h"
#include "solver/nls/loss.h"
#include "solver/nls/pose.h"

namespace cdpr {

class PosePriorFactor final : public Factor {
 public:
  PosePriorFactor(int pose_index, const Pose& measured, double sigma_position_m, double sigma_orientation_rad,
                  Loss loss);

  int residual_dim() const override { return 6; }
  std::span<const Key> keys() const override { return keys_; }
  bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                double* cost) const override;

 private:
  std::array<Key, 1> keys_;
  Pose measured_;
  double sigma_position_m_;
  double sigma_orientation_rad_;
  Loss loss_;
};

}  // namespace cdpr
