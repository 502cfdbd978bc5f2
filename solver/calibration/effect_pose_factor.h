#pragma once
// The kineto-static factor of one static pose (as solver/calibration/static_pose_factor.h:
// Eq. 14-16 coupled by the statics of Eq. 5-11) with optional model terms
// (solver/model/effects.h), each read from its own EffectKey variable:
//   encoder i:  ((1 + s_i) payout_i + l0_i - z_enc,i) / sigma_encoder
//   height i:   (b_z,i - z_i) / sigma_height
//   force:      ((1 + g) |(f_h, f_v)_ref| + b - z_force) / sigma_force (b of load_cell or load_cell_bias)
// payout_i and z_i from solver/model/effect_cable.h (elasticity, density error,
// swivel pulley), the statics with the weight at the nominal CoM + c and, with
// a pose reference offset d, the platform origin at p - R d (the pose
// variable is then the localization's reference point; effects.h).
// With no effects it is the base catenary model (payout = arc length).
// The Loss applies to the reading rows only (solver/calibration/pose_factor_rows.h).
//
// Variables, in keys() order: PoseKey(k), ReferenceForceKey(k),
// AnchorKey(0..3), OffsetKey(0..3), then EffectKey(e) for each effect in the
// order given. Evaluation allocates nothing.

#include <array>
#include <vector>

#include "solver/model/effects.h"
#include "solver/nls/factor.h"
#include "solver/nls/loss.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr {

// The model's view of one pose at given variable values, in physical units,
// for residual analysis (solver/ diagnosis, reports).
struct PosePrediction {
  std::array<double, kCableCount> payout_m{};          // modelled unstretched cable, A to attachment
  std::array<double, kCableCount> tension_n{};         // |(f_h, f_v)| at the attachment
  std::array<double, kCableCount> encoder_residual_m{};  // model reading - measured reading
  std::array<double, kCableCount> height_residual_m{};   // attachment height - cable end height
  double force_residual_n = 0.0;                       // model load-cell reading - measured
};

class EffectPoseFactor final : public Factor {
 public:
  static constexpr int kResidualDim = 2 * kCableCount + 1;
  static constexpr int kBaseKeyCount = 2 + 2 * kCableCount;

  // `robot` must outlive the factor; `effects` without repeats; sigma_height_m
  // as StaticPoseFactor's.
  EffectPoseFactor(const Robot& robot, int pose_index, const Sample& sample, double sigma_height_m, Loss loss,
                   const std::vector<Effect>& effects);

  int residual_dim() const override { return kResidualDim; }
  std::span<const Key> keys() const override { return keys_; }
  bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                double* cost) const override;
  // Same parameters as evaluate(); false where the model cannot be evaluated.
  bool predict(const double* const* parameters, PosePrediction& out) const;

 private:
  // Whitened residuals, Jacobians (if non-null) and the prediction (if non-null).
  bool evaluate_model(const double* const* parameters, double* residual, double* const* jacobians,
                      PosePrediction* prediction) const;
  // The parameter block of effect e, or null when the effect is not modelled.
  const double* effect_parameter(const double* const* parameters, Effect e) const;
  double* effect_jacobian(double* const* jacobians, Effect e) const;

  const Robot& robot_;
  std::vector<Key> keys_;
  std::vector<int> block_dims_;
  std::array<int, kEffectCount> effect_slot_;  // index into keys_, -1 when absent
  std::array<double, kCableCount> encoder_m_;
  double force_n_;
  SampleSigmas sigma_;  // the row's reading sigmas (reading_sigmas())
  LeftOutRows left_out_;  // readings left out as gross errors (Sample::encoder_left_out, force_left_out)
  double sigma_height_m_;
  Loss loss_;
};

}  // namespace cdpr
