#include "solver/static_pose_factor.h"

#include <cmath>

#include "solver/catenary.h"
#include "solver/factor_support.h"
#include "solver/platform_statics.h"

namespace cdpr {
namespace {

// Tangent sizes of the variables, in keys() order.
constexpr std::array<int, StaticPoseFactor::kKeyCount> kBlockDims = {6, 2, 3, 3, 3, 3, 1, 1, 1, 1};

using ResidualRow = Eigen::Matrix<double, 1, kStaticsParamDim>;

// Copies the statics-parameter columns of one residual row into the factor's
// Jacobian blocks (pose, reference force, anchors); offsets are set separately.
void scatter_row(const ResidualRow& row, int r, double* const* jacobians) {
  constexpr int kDim = StaticPoseFactor::kResidualDim;
  static_assert(kStaticsPose == 0 && kStaticsForce == 6 && kStaticsAnchor == 8);
  if (jacobians[0]) for (int c = 0; c < 6; ++c) jacobians[0][r * 6 + c] = row(kStaticsPose + c);
  if (jacobians[1]) for (int c = 0; c < 2; ++c) jacobians[1][r * 2 + c] = row(kStaticsForce + c);
  for (int i = 0; i < kCableCount; ++i) {
    if (jacobians[2 + i]) for (int c = 0; c < 3; ++c) jacobians[2 + i][r * 3 + c] = row(kStaticsAnchor + 3 * i + c);
    if (jacobians[2 + kCableCount + i]) jacobians[2 + kCableCount + i][r] = 0.0;
  }
  (void)kDim;
}

}  // namespace

StaticPoseFactor::StaticPoseFactor(const Robot& robot, int pose_index, const Sample& sample, double sigma_height_m,
                                   Loss loss)
    : robot_(robot),
      encoder_m_(sample.encoder_m),
      force_n_(sample.force_n),
      sigma_height_m_(sigma_height_m),
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
  const double sigma_encoder = robot_.noise.encoder_m;
  for (int i = 0; i < kCableCount; ++i) {
    const CableStatics& c = cables[i];
    // A cable pushing (f_h <= 0) has no catenary: the point is outside the model.
    if (!(c.f_h > 0.0)) return false;
    const CatenaryOutput shape = evaluate_catenary({c.f_h, c.f_v, c.span, c.anchor_z, weight_per_length}, with_jacobian);
    const double offset = parameters[2 + kCableCount + i][0];
    residual[i] = (shape.arc_length + offset - encoder_m_[i]) / sigma_encoder;                 // Eq. (14)
    residual[kCableCount + i] = (c.attachment_z - shape.end_height) / sigma_height_m_;         // Eq. (15)
    if (!with_jacobian) continue;

    // Chain rule through (f_h, f_v, span, anchor_z) of the catenary.
    const ResidualRow d_length = shape.d_arc_length(0) * c.d_f_h + shape.d_arc_length(1) * c.d_f_v +
                                 shape.d_arc_length(2) * c.d_span + shape.d_arc_length(3) * c.d_anchor_z;
    const ResidualRow d_height = shape.d_end_height(0) * c.d_f_h + shape.d_end_height(1) * c.d_f_v +
                                 shape.d_end_height(2) * c.d_span + shape.d_end_height(3) * c.d_anchor_z;
    scatter_row(d_length / sigma_encoder, i, jacobians);
    scatter_row((c.d_attachment_z - d_height) / sigma_height_m_, kCableCount + i, jacobians);
    if (jacobians[2 + kCableCount + i]) jacobians[2 + kCableCount + i][i] = 1.0 / sigma_encoder;
  }

  // Eq. (16): the load cell measures the tension magnitude of the reference cable.
  const int force_row = 2 * kCableCount;
  const double tension = in.reference_force.norm();
  const double sigma_force = robot_.noise.force_n;
  residual[force_row] = (tension - force_n_) / sigma_force;
  if (with_jacobian) {
    ResidualRow row = ResidualRow::Zero();
    if (tension > 0.0) {
      row(kStaticsForce) = in.reference_force.x() / (tension * sigma_force);
      row(kStaticsForce + 1) = in.reference_force.y() / (tension * sigma_force);
    }
    scatter_row(row, force_row, jacobians);
  }
  *cost = apply_loss(loss_, kResidualDim, residual, jacobians, kBlockDims);
  return true;
}

}  // namespace cdpr
