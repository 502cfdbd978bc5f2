#pragma once
// The kineto-static factor of one static pose k (paper Sec. IV-C): the
// encoder (Eq. 14), attachment-height (Eq. 15) and reference-force (Eq. 16)
// residuals of all four cables, which the statics of Eq. (11) couple.
//
// Variables: PoseKey(k), ReferenceForceKey(k), AnchorKey(0..3), OffsetKey(0..3).
// Residuals (whitened by their sigma; the Loss robustifies the readings,
// encoder and force rows, not the height identity, solver/calibration/pose_factor_rows.h):
//   [0..3] encoder i:   (l_C,i + l0_i - z_enc,i) / sigma_encoder
//   [4..7] height i:    (b_z,i - z_i(L_i)) / sigma_height
//   [8]    force:       (|(f_h, f_v)_ref| - z_force) / sigma_force

#include <array>

#include "solver/nls/factor.h"
#include "solver/nls/loss.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr {

class StaticPoseFactor final : public Factor {
 public:
  static constexpr int kResidualDim = 2 * kCableCount + 1;
  static constexpr int kKeyCount = 2 + 2 * kCableCount;

  // `robot` must outlive the factor; sigma_height_m weights Eq. (15) (for a
  // row with its own sigmas, scaled as row_height_sigma() says).
  StaticPoseFactor(const Robot& robot, int pose_index, const Sample& sample, double sigma_height_m, Loss loss);

  int residual_dim() const override { return kResidualDim; }
  std::span<const Key> keys() const override { return keys_; }
  bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                double* cost) const override;
  // The pose and the anchors reach the encoder and height rows, the
  // reference force every row and offset i only encoder row i (Eq. 14).
  RowRange jacobian_rows(int k) const override {
    if (k >= 2 + kCableCount) return {k - 2 - kCableCount, k - 1 - kCableCount};
    return {0, k == 1 ? kResidualDim : 2 * kCableCount};
  }

 private:
  const Robot& robot_;
  std::array<Key, kKeyCount> keys_;
  std::array<double, kCableCount> encoder_m_;
  double force_n_;
  SampleSigmas sigma_;  // the row's reading sigmas (reading_sigmas())
  LeftOutRows left_out_;  // readings left out as gross errors (Sample::encoder_left_out, force_left_out)
  double sigma_height_m_;
  Loss loss_;
};

}  // namespace cdpr
