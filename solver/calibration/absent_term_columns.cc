#include "solver/calibration/absent_term_columns.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/calibration/effect_pose_factor.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/model/catenary.h"
#include "solver/model/platform_statics.h"
#include "solver/nls/factor_support.h"

namespace cdpr {
namespace {

// How a cable's payout P and end height E move per unit of a scalar term's
// parameter; its reading rows follow as EffectPoseFactor whitens them.
struct ShapeChange {
  double payout = 0.0, end_height = 0.0;
};

}  // namespace

bool absent_term_jacobians(const Robot& robot, const BaseFitRow& row, double height_sigma_m, const Loss& loss,
                           const std::vector<Effect>& effects, double* const* jacobians) {
  constexpr int kRows = EffectPoseFactor::kResidualDim;
  StaticsInput in;
  in.world_T_platform = row.world_T_platform;
  in.reference_force = row.reference_force;
  in.anchor_world = row.anchor_world;
  std::array<CableStatics, kCableCount> cables;
  if (solve_platform_statics(robot, in, true, cables) != StaticsStatus::kOk) return false;

  std::array<double*, kEffectCount> block{};
  std::array<int, kEffectCount> dims{};
  for (std::size_t j = 0; j < effects.size(); ++j) {
    const int e = static_cast<int>(effects[j]);
    block[e] = jacobians[j];
    dims[j] = effect_dimension(effects[j]);
    std::fill(jacobians[j], jacobians[j] + kRows * dims[j], 0.0);
  }
  auto at = [&](Effect e) { return block[static_cast<int>(e)]; };

  const Eigen::Matrix3d world_R_platform = row.world_T_platform.world_R_platform.toRotationMatrix();
  const SampleSigmas sigma = reading_sigmas(robot, row.sample);
  const double sigma_height = row_height_sigma(robot, row.sample, height_sigma_m);
  const double w = robot.gravity_mps2 * robot.cable_linear_density_kgpm;
  std::array<double, kRows> residual;
  for (int i = 0; i < kCableCount; ++i) {
    const CableStatics& c = cables[i];
    if (!(c.f_h > 0.0)) return false;
    const CatenaryOutput shape = evaluate_catenary({c.f_h, c.f_v, c.span, c.anchor_z, w}, true);
    const double sigma_encoder = sigma.encoder_m[i];
    const int enc_row = encoder_row(i), height_row = kCableCount + i;
    // As StaticPoseFactor: the loss below scales the rows by these.
    residual[enc_row] = (shape.arc_length + row.offset_m[i] - row.sample.encoder_m[i]) / sigma_encoder;
    residual[height_row] = (c.attachment_z - shape.end_height) / sigma_height;
    auto write = [&](double* b, const ShapeChange& d) {
      if (!b) return;
      b[enc_row] = d.payout / sigma_encoder;
      b[height_row] = -d.end_height / sigma_height;
    };
    // With l0 the arc length and (h, v) the force at the platform, the
    // other end pulls with v1 = v + w l0 and T1 = |(h, v1)| and leaves at
    // phi = atan2(h, v1) (effect_cable.cc's free cable at c = 0, r = 0).
    const double h = c.f_h, v = c.f_v, l0 = shape.arc_length;
    const double v1 = v + w * l0, t1 = std::hypot(h, v1);
    const auto& dp = shape.d_arc_length;
    const auto& de = shape.d_end_height;
    // The cable's shape depends on (h / w, v / w) alone, so w d/dw = -(h d/dh + v d/dv).
    write(at(Effect::kDensityError), {-(h * dp(0) + v * dp(1)), -(h * de(0) + v * de(1))});
    // Compliance c (kappa 1e-6): span = x(l0, c) moves l0 by
    // dl0/dc = -x_c / x_l0 = -l0 T1, and E by -(z_c + z_l0 dl0/dc) = w l0^2 / 2.
    write(at(Effect::kElasticity), {-l0 * t1 * kComplianceScale, 0.5 * w * l0 * l0 * kComplianceScale});
    // Pulley radius r: span = x(l0) + r (1 + cos phi) shortens l0 by
    // (1 + cos phi) / x_l0 = (T1 + v1) / h, the wrap adds pi - phi to P; the
    // departure point rises by sin phi = h / T1 and the shorter free cable
    // raises E by z_l0 = v1 / T1 times its shortening.
    write(at(Effect::kPulleyRadius),
          {std::numbers::pi - std::atan2(h, v1) - (t1 + v1) / h, h / t1 + v1 * (t1 + v1) / (h * t1)});
    // Encoder scale s_i: P (1 + s_i) on its own cable's reading.
    if (double* scale = at(Effect::kEncoderScale)) scale[enc_row * kCableCount + i] = l0 / sigma_encoder;
    // How the payout and the height residual move per unit of statics
    // parameter s (the forces, span and anchor height move), chained through
    // the catenary as the pose's columns are.
    const auto payout_by = [&](int s) {
      return dp(0) * c.d_f_h(s) + dp(1) * c.d_f_v(s) + dp(2) * c.d_span(s) + dp(3) * c.d_anchor_z(s);
    };
    const auto height_by = [&](int s) {
      return c.d_attachment_z(s) - (de(0) * c.d_f_h(s) + de(1) * c.d_f_v(s) + de(2) * c.d_span(s) + de(3) * c.d_anchor_z(s));
    };
    // CoM offset: the statics' own columns.
    if (double* com = at(Effect::kComOffset)) {
      for (int a = 0; a < 3; ++a) {
        com[enc_row * 3 + a] = payout_by(kStaticsCom + a) / sigma_encoder;
        com[height_row * 3 + a] = height_by(kStaticsCom + a) / sigma_height;
      }
    }
    // Pose reference offset d: the platform origin is p - R d, so d's
    // columns are the origin's times -R (effect_pose_factor.cc).
    if (double* reference = at(Effect::kPoseReferenceOffset)) {
      for (int a = 0; a < 3; ++a) {
        double payout = 0.0, height = 0.0;
        for (int b = 0; b < 3; ++b) {
          payout -= payout_by(kStaticsPose + b) * world_R_platform(b, a);
          height -= height_by(kStaticsPose + b) * world_R_platform(b, a);
        }
        reference[enc_row * 3 + a] = payout / sigma_encoder;
        reference[height_row * 3 + a] = height / sigma_height;
      }
    }
  }
  const double tension = row.reference_force.norm();
  residual[kForceRow] = (tension - row.sample.force_n) / sigma.force_n;
  if (double* load_cell = at(Effect::kLoadCell)) {
    load_cell[kForceRow * 2] = 1.0 / sigma.force_n;
    load_cell[kForceRow * 2 + 1] = tension / sigma.force_n;
  }
  if (double* bias = at(Effect::kLoadCellBias)) bias[kForceRow] = 1.0 / sigma.force_n;

  const std::span<const int> block_dims(dims.data(), effects.size());
  const LeftOutRows left_out = left_out_rows(row.sample);
  zero_rows(std::span(left_out.rows.data(), left_out.count), residual.data(), jacobians, block_dims);
  apply_loss_to_rows(loss, kReadingRows, kRows, residual.data(), jacobians, block_dims);
  return true;
}

}  // namespace cdpr
