#include "solver/calibration/static_pose_factor.h"

#include <cmath>

#include "solver/model/catenary.h"
#include "solver/nls/factor_support.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/model/platform_statics.h"

namespace cdpr {
namespace {

// Tangent sizes of the variables, in keys() order.
constexpr std::array<int, StaticPoseFactor::kKeyCount> kStaticPoseBlockDims = {6, 2, 3, 3, 3, 3, 1, 1, 1, 1};

// One residual row's derivative as the chain rule through a cable's catenary
// inputs: sum_k weight[k] * (d f_h, d f_v, d span, d anchor_z)[k], each a
// statics row (plus the attachment height's row for the height residual).
struct ChainWeights {
  double f_h = 0.0, f_v = 0.0, span = 0.0, anchor_z = 0.0;
};

// Rows `cable` (encoder, Eq. 14) and kCableCount + cable (height, Eq. 15) of
// the factor's Jacobian blocks of pose, reference force and anchors (the
// offsets' are write_offset_columns'), straight from the cable's statics rows; the height row adds
// `height_attachment_z` times the attachment height's row. Only the forces
// depend on everything; the geometry does not (platform_statics.h): the
// span depends on the pose and the cable's own anchor, the anchor height on
// that anchor alone, the attachment height on the pose alone, none of them
// on the reference force. So each block sums only the rows that reach it,
// instead of five 23-wide rows scaled, added and copied. Both rows at once share the loads
// of the statics rows, and whole segments let Eigen vectorise the sums.
void write_chain_rows(const CableStatics& c, int cable, const ChainWeights& encoder, const ChainWeights& height,
                      double height_attachment_z, double* const* jacobians) {
  static_assert(kStaticsPose == 0 && kStaticsForce == 6 && kStaticsAnchor == 8);
  const int encoder_row = cable, height_row = kCableCount + cable;
  if (double* pose = jacobians[0]) {
    const auto f_h = c.d_f_h.head<6>(), f_v = c.d_f_v.head<6>(), span = c.d_span.head<6>();
    Eigen::Map<Eigen::Matrix<double, 1, 6>>(pose + encoder_row * 6) =
        encoder.f_h * f_h + encoder.f_v * f_v + encoder.span * span;
    Eigen::Map<Eigen::Matrix<double, 1, 6>>(pose + height_row * 6) =
        height.f_h * f_h + height.f_v * f_v + height.span * span + height_attachment_z * c.d_attachment_z.head<6>();
  }
  if (double* force = jacobians[1]) {
    const auto f_h = c.d_f_h.segment<2>(kStaticsForce), f_v = c.d_f_v.segment<2>(kStaticsForce);
    Eigen::Map<Eigen::Matrix<double, 1, 2>>(force + encoder_row * 2) = encoder.f_h * f_h + encoder.f_v * f_v;
    Eigen::Map<Eigen::Matrix<double, 1, 2>>(force + height_row * 2) = height.f_h * f_h + height.f_v * f_v;
  }
  for (int i = 0; i < kCableCount; ++i) {
    if (double* anchor = jacobians[2 + i]) {
      const int first = kStaticsAnchor + 3 * i;
      const auto f_h = c.d_f_h.segment<3>(first), f_v = c.d_f_v.segment<3>(first);
      Eigen::Map<Eigen::Matrix<double, 1, 3>> encoder_part(anchor + encoder_row * 3);
      Eigen::Map<Eigen::Matrix<double, 1, 3>> height_part(anchor + height_row * 3);
      encoder_part = encoder.f_h * f_h + encoder.f_v * f_v;
      height_part = height.f_h * f_h + height.f_v * f_v;
      if (i == cable) {
        const auto span = c.d_span.segment<3>(first), anchor_z = c.d_anchor_z.segment<3>(first);
        encoder_part += encoder.span * span + encoder.anchor_z * anchor_z;
        height_part += height.span * span + height.anchor_z * anchor_z;
      }
    }
  }
}

// The force row (Eq. 16) depends on the reference force alone.
void write_force_row(const Eigen::Vector2d& d_force, int r, double* const* jacobians) {
  if (jacobians[0]) for (int c = 0; c < 6; ++c) jacobians[0][r * 6 + c] = 0.0;
  if (jacobians[1]) for (int c = 0; c < 2; ++c) jacobians[1][r * 2 + c] = d_force(c);
  for (int i = 0; i < kCableCount; ++i) {
    if (jacobians[2 + i]) for (int c = 0; c < 3; ++c) jacobians[2 + i][r * 3 + c] = 0.0;
  }
}

// Offset i reaches its own encoder row alone (Eq. 14): each offset's
// column is written whole, once.
void write_offset_columns(const std::array<double, kCableCount>& sigma_encoder, double* const* jacobians) {
  for (int i = 0; i < kCableCount; ++i) {
    if (double* offset = jacobians[2 + kCableCount + i]) {
      Eigen::Map<Eigen::Matrix<double, StaticPoseFactor::kResidualDim, 1>>(offset).setZero();
      offset[i] = 1.0 / sigma_encoder[i];
    }
  }
}

}  // namespace

StaticPoseFactor::StaticPoseFactor(const Robot& robot, int pose_index, const Sample& sample, double sigma_height_m,
                                   Loss loss)
    : robot_(robot),
      encoder_m_(sample.encoder_m),
      force_n_(sample.force_n),
      sigma_(reading_sigmas(robot, sample)),
      left_out_(left_out_rows(sample)),
      sigma_height_m_(row_height_sigma(robot, sample, sigma_height_m)),
      loss_(loss) {
  keys_[0] = PoseKey(pose_index);
  keys_[1] = ReferenceForceKey(pose_index);
  for (int i = 0; i < kCableCount; ++i) {
    keys_[2 + i] = AnchorKey(i);
    keys_[2 + kCableCount + i] = OffsetKey(i);
  }
}

bool StaticPoseFactor::evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                                double* cost) const {
  StaticsInput in;
  in.world_T_platform = pose_from_parameters(parameters[0]);
  in.reference_force = Eigen::Vector2d(parameters[1][0], parameters[1][1]);
  for (int i = 0; i < kCableCount; ++i) {
    in.anchor_world[i] = Eigen::Vector3d(parameters[2 + i][0], parameters[2 + i][1], parameters[2 + i][2]);
  }
  const bool with_jacobian = jacobians != nullptr;
  std::array<CableStatics, kCableCount> cables;
  if (solve_platform_statics(robot_, in, with_jacobian, cables) != StaticsStatus::kOk) return false;

  const double weight_per_length = robot_.gravity_mps2 * robot_.cable_linear_density_kgpm;
  for (int i = 0; i < kCableCount; ++i) {
    const double sigma_encoder = sigma_.encoder_m[i];
    const CableStatics& c = cables[i];
    // A cable pushing (f_h <= 0) has no catenary: the point is outside the model.
    if (!(c.f_h > 0.0)) return false;
    const CatenaryOutput shape = evaluate_catenary({c.f_h, c.f_v, c.span, c.anchor_z, weight_per_length}, with_jacobian);
    const double offset = parameters[2 + kCableCount + i][0];
    residual[i] = (shape.arc_length + offset - encoder_m_[i]) / sigma_encoder;                 // Eq. (14)
    residual[kCableCount + i] = (c.attachment_z - shape.end_height) / sigma_height_m_;         // Eq. (15)
    if (!with_jacobian) continue;

    // Chain rule through (f_h, f_v, span, anchor_z) of the catenary, whitened.
    const Eigen::Matrix<double, 1, 4>& dl = shape.d_arc_length;
    const Eigen::Matrix<double, 1, 4>& dz = shape.d_end_height;
    const double to_encoder = 1.0 / sigma_encoder, to_height = 1.0 / sigma_height_m_;
    write_chain_rows(c, i, {dl(0) * to_encoder, dl(1) * to_encoder, dl(2) * to_encoder, dl(3) * to_encoder},
                     {-dz(0) * to_height, -dz(1) * to_height, -dz(2) * to_height, -dz(3) * to_height}, to_height,
                     jacobians);
  }

  // Eq. (16): the load cell measures the tension magnitude of the reference cable.
  const int force_row = 2 * kCableCount;
  const double tension = in.reference_force.norm();
  const double sigma_force = sigma_.force_n;
  residual[force_row] = (tension - force_n_) / sigma_force;
  if (with_jacobian) {
    const Eigen::Vector2d d_force =
        tension > 0.0 ? Eigen::Vector2d(in.reference_force / (tension * sigma_force)) : Eigen::Vector2d::Zero();
    write_force_row(d_force, force_row, jacobians);
    write_offset_columns(sigma_.encoder_m, jacobians);
  }
  zero_rows(std::span(left_out_.rows.data(), left_out_.count), residual, jacobians, kStaticPoseBlockDims);
  *cost = apply_loss_to_rows(loss_, kReadingRows, kResidualDim, residual, jacobians, kStaticPoseBlockDims);
  return true;
}

}  // namespace cdpr
