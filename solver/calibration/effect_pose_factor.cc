#include "solver/calibration/effect_pose_factor.h"

#include <algorithm>
#include <cmath>

#include "solver/model/effect_cable.h"
#include "solver/nls/factor_support.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/model/platform_statics.h"

namespace cdpr {
namespace {

using StatRow = Eigen::Matrix<double, 1, kStaticsParamDim>;

// With a pose reference offset d the pose variable (p, R) is the
// localization's reference point and the statics see the platform origin
// p' = p - R d. Perturbing R by Exp(dtheta) moves p' by R [d]x dtheta, so a
// row's rotation columns gain (its p' columns) R [d]x and d's own columns
// are -(its p' columns) R. Inactive (d = 0, no block): the pose's own.
struct ReferenceOffset {
  Eigen::Matrix3d world_R_platform = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rotation_gain = Eigen::Matrix3d::Zero();  // R [d]x
  double* block = nullptr;                                  // d's Jacobian block, if modelled
};

// Copies the statics-parameter columns of one residual row into the
// Jacobian blocks of pose, reference force, anchors and (if modelled) the
// CoM offset and the pose reference offset; offsets get 0 here and their
// entry separately.
void scatter_statics(const StatRow& row, int r, double* const* jacobians, double* com_block,
                     const ReferenceOffset& reference) {
  static_assert(kStaticsPose == 0 && kStaticsForce == 6 && kStaticsAnchor == 8 && kStaticsCom == 20);
  const Eigen::RowVector3d origin = row.segment<3>(kStaticsPose);
  if (jacobians[0]) {
    const Eigen::RowVector3d rotation = row.segment<3>(kStaticsPose + 3) + origin * reference.rotation_gain;
    for (int c = 0; c < 3; ++c) {
      jacobians[0][r * 6 + c] = origin(c);
      jacobians[0][r * 6 + 3 + c] = rotation(c);
    }
  }
  if (reference.block) {
    const Eigen::RowVector3d d_offset = -origin * reference.world_R_platform;
    for (int c = 0; c < 3; ++c) reference.block[r * 3 + c] = d_offset(c);
  }
  if (jacobians[1]) for (int c = 0; c < 2; ++c) jacobians[1][r * 2 + c] = row(kStaticsForce + c);
  for (int i = 0; i < kCableCount; ++i) {
    if (jacobians[2 + i]) for (int c = 0; c < 3; ++c) jacobians[2 + i][r * 3 + c] = row(kStaticsAnchor + 3 * i + c);
    if (jacobians[2 + kCableCount + i]) jacobians[2 + kCableCount + i][r] = 0.0;
  }
  if (com_block) for (int c = 0; c < 3; ++c) com_block[r * 3 + c] = row(kStaticsCom + c);
}

// d out / d statics parameters through the cable inputs (f_h, f_v, span, anchor_z).
StatRow chain(const EffectCableRow& d, const CableStatics& c) {
  return d(kCableFh) * c.d_f_h + d(kCableFv) * c.d_f_v + d(kCableSpan) * c.d_span + d(kCableAnchorZ) * c.d_anchor_z;
}

}  // namespace

EffectPoseFactor::EffectPoseFactor(const Robot& robot, int pose_index, const Sample& sample, double sigma_height_m,
                                   Loss loss, const std::vector<Effect>& effects)
    : robot_(robot),
      encoder_m_(sample.encoder_m),
      force_n_(sample.force_n),
      sigma_(reading_sigmas(robot, sample)),
      left_out_(left_out_rows(sample)),
      sigma_height_m_(row_height_sigma(robot, sample, sigma_height_m)),
      loss_(loss) {
  const std::size_t blocks = 2 + 2 * kCableCount + effects.size();
  keys_.reserve(blocks);
  block_dims_.reserve(blocks);
  keys_ = {PoseKey(pose_index), ReferenceForceKey(pose_index)};
  block_dims_ = {6, 2};
  for (int i = 0; i < kCableCount; ++i) {
    keys_.push_back(AnchorKey(i));
    block_dims_.push_back(3);
  }
  for (int i = 0; i < kCableCount; ++i) {
    keys_.push_back(OffsetKey(i));
    block_dims_.push_back(1);
  }
  effect_slot_.fill(-1);
  for (Effect e : effects) {
    effect_slot_[static_cast<int>(e)] = static_cast<int>(keys_.size());
    keys_.push_back(EffectKey(e));
    block_dims_.push_back(effect_dimension(e));
  }
}

const double* EffectPoseFactor::effect_parameter(const double* const* parameters, Effect e) const {
  const int slot = effect_slot_[static_cast<int>(e)];
  return slot < 0 ? nullptr : parameters[slot];
}

double* EffectPoseFactor::effect_jacobian(double* const* jacobians, Effect e) const {
  const int slot = effect_slot_[static_cast<int>(e)];
  return slot < 0 || jacobians == nullptr ? nullptr : jacobians[slot];
}

bool EffectPoseFactor::evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                                double* cost) const {
  if (!evaluate_model(parameters, residual, jacobians, nullptr)) return false;
  zero_rows(std::span(left_out_.rows.data(), left_out_.count), residual, jacobians, block_dims_);
  *cost = apply_loss_to_rows(loss_, kReadingRows, kResidualDim, residual, jacobians, block_dims_);
  return true;
}

bool EffectPoseFactor::predict(const double* const* parameters, PosePrediction& out) const {
  std::array<double, kResidualDim> residual;
  return evaluate_model(parameters, residual.data(), nullptr, &out);
}

bool EffectPoseFactor::evaluate_model(const double* const* parameters, double* residual, double* const* jacobians,
                                      PosePrediction* prediction) const {
  const double* scale = effect_parameter(parameters, Effect::kEncoderScale);
  const double* load_cell = effect_parameter(parameters, Effect::kLoadCell);  // (bias, gain)
  const double* bias_only = effect_parameter(parameters, Effect::kLoadCellBias);
  const double* com = effect_parameter(parameters, Effect::kComOffset);
  const double* density = effect_parameter(parameters, Effect::kDensityError);
  const double* kappa = effect_parameter(parameters, Effect::kElasticity);
  const double* radius = effect_parameter(parameters, Effect::kPulleyRadius);
  const double* reference_offset = effect_parameter(parameters, Effect::kPoseReferenceOffset);

  StaticsInput in;
  in.world_T_platform = pose_from_parameters(parameters[0]);
  ReferenceOffset reference;
  if (reference_offset) {
    const Eigen::Vector3d d(reference_offset[0], reference_offset[1], reference_offset[2]);
    reference.world_R_platform = in.world_T_platform.world_R_platform.toRotationMatrix();
    reference.rotation_gain = reference.world_R_platform * skew(d);
    in.world_T_platform.position_world -= reference.world_R_platform * d;
  }
  in.reference_force = Eigen::Vector2d(parameters[1][0], parameters[1][1]);
  for (int i = 0; i < kCableCount; ++i) {
    in.anchor_world[i] = Eigen::Vector3d(parameters[2 + i][0], parameters[2 + i][1], parameters[2 + i][2]);
  }
  if (com) in.com_offset_platform = Eigen::Vector3d(com[0], com[1], com[2]);
  const bool with_jacobian = jacobians != nullptr;
  std::array<CableStatics, kCableCount> cables;
  if (solve_platform_statics(robot_, in, with_jacobian, cables) != StaticsStatus::kOk) return false;

  if (with_jacobian) {
    for (Effect e : kAllEffects) {
      if (double* J = effect_jacobian(jacobians, e)) std::fill(J, J + kResidualDim * effect_dimension(e), 0.0);
    }
  }
  double* const com_block = effect_jacobian(jacobians, Effect::kComOffset);
  double* const scale_block = effect_jacobian(jacobians, Effect::kEncoderScale);
  double* const density_block = effect_jacobian(jacobians, Effect::kDensityError);
  double* const kappa_block = effect_jacobian(jacobians, Effect::kElasticity);
  double* const radius_block = effect_jacobian(jacobians, Effect::kPulleyRadius);
  reference.block = effect_jacobian(jacobians, Effect::kPoseReferenceOffset);

  const double nominal_weight = robot_.gravity_mps2 * robot_.cable_linear_density_kgpm;
  for (int i = 0; i < kCableCount; ++i) {
    const double sigma_encoder = sigma_.encoder_m[i];
    const CableStatics& c = cables[i];
    // A cable pushing (f_h <= 0) has no catenary: the point is outside the model.
    if (!(c.f_h > 0.0)) return false;
    EffectCableInput cable{c.f_h, c.f_v, c.span, c.anchor_z, nominal_weight * (1.0 + (density ? density[0] : 0.0)),
                           kappa ? kappa[0] * kComplianceScale : 0.0, radius ? radius[0] : 0.0};
    EffectCableOutput shape;
    if (!evaluate_effect_cable(cable, with_jacobian, shape)) return false;
    const double gain_i = 1.0 + (scale ? scale[i] : 0.0);
    const double offset = parameters[2 + kCableCount + i][0];
    const int enc_row = i, height_row = kCableCount + i;
    residual[enc_row] = (gain_i * shape.payout + offset - encoder_m_[i]) / sigma_encoder;  // Eq. (14)
    residual[height_row] = (c.attachment_z - shape.end_height) / sigma_height_m_;            // Eq. (15)
    if (prediction) {
      prediction->payout_m[i] = shape.payout;
      prediction->tension_n[i] = std::hypot(c.f_h, c.f_v);
      prediction->encoder_residual_m[i] = residual[enc_row] * sigma_encoder;
      prediction->height_residual_m[i] = residual[height_row] * sigma_height_m_;
    }
    if (!with_jacobian) continue;

    scatter_statics(gain_i * chain(shape.d_payout, c) / sigma_encoder, enc_row, jacobians, com_block, reference);
    scatter_statics((c.d_attachment_z - chain(shape.d_end_height, c)) / sigma_height_m_, height_row, jacobians,
                    com_block, reference);
    if (jacobians[2 + kCableCount + i]) jacobians[2 + kCableCount + i][enc_row] = 1.0 / sigma_encoder;
    if (scale_block) scale_block[enc_row * kCableCount + i] = shape.payout / sigma_encoder;
    // Scalar effects of the cable shape, through the cable model's own columns.
    const auto shape_column = [&](double* block, int column, double d_parameter) {
      if (!block) return;
      block[enc_row] = gain_i * shape.d_payout(column) * d_parameter / sigma_encoder;
      block[height_row] = -shape.d_end_height(column) * d_parameter / sigma_height_m_;
    };
    shape_column(density_block, kCableWeight, nominal_weight);
    shape_column(kappa_block, kCableCompliance, kComplianceScale);
    shape_column(radius_block, kCableRadius, 1.0);
  }

  // Eq. (16) with the load cell's bias and gain.
  const int force_row = 2 * kCableCount;
  const double tension = in.reference_force.norm();
  const double force_gain = 1.0 + (load_cell ? load_cell[1] : 0.0);
  const double sigma_force = sigma_.force_n;
  // The two biases add, so the Jacobians stay exact even for a model that has
  // both (calibrate() refuses one; the factor need not).
  const double bias = (load_cell ? load_cell[0] : 0.0) + (bias_only ? bias_only[0] : 0.0);
  residual[force_row] = (force_gain * tension + bias - force_n_) / sigma_force;
  if (prediction) prediction->force_residual_n = residual[force_row] * sigma_force;
  if (with_jacobian) {
    StatRow row = StatRow::Zero();
    if (tension > 0.0) {
      row(kStaticsForce) = force_gain * in.reference_force.x() / (tension * sigma_force);
      row(kStaticsForce + 1) = force_gain * in.reference_force.y() / (tension * sigma_force);
    }
    scatter_statics(row, force_row, jacobians, com_block, reference);
    if (double* J = effect_jacobian(jacobians, Effect::kLoadCell)) {
      J[force_row * 2] = 1.0 / sigma_force;
      J[force_row * 2 + 1] = tension / sigma_force;
    }
    if (double* J = effect_jacobian(jacobians, Effect::kLoadCellBias)) J[force_row] = 1.0 / sigma_force;
  }
  return true;
}

}  // namespace cdpr
