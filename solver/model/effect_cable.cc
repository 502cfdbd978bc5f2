#include "solver/model/effect_cable.h"

#include <cmath>
#include <numbers>

#include <Eigen/LU>

#include "solver/model/catenary.h"

namespace cdpr {
namespace {

// The free elastic catenary of unstretched length L0 (header) and its
// partial derivatives, written to avoid the cancellations of taut cables
// (small w L0 / T): T1 - T0 = w L0 (V1 + V) / (T1 + T0), and
// sinh(asinh a - asinh b) = a sqrt(1 + b^2) - b sqrt(1 + a^2).
struct FreeCable {
  double v1 = 0.0, t0 = 0.0, t1 = 0.0;
  double x = 0.0, z = 0.0;
  // Partials with respect to (f_h, f_v, w, c, L0).
  double x_h = 0.0, x_v = 0.0, x_w = 0.0, x_c = 0.0, x_l0 = 0.0;
  double z_h = 0.0, z_v = 0.0, z_w = 0.0, z_c = 0.0, z_l0 = 0.0;
};

FreeCable free_cable(double h, double v, double w, double c, double l0) {
  FreeCable f;
  f.v1 = v + w * l0;
  f.t0 = std::hypot(h, v);
  f.t1 = std::hypot(h, f.v1);
  const double sum_v = f.v1 + v;
  const double sum_t = f.t1 + f.t0;
  // q = sinh(A) / w with A = asinh(V1 / h) - asinh(V / h).
  const double q = f.v1 * v > 0.0 ? l0 * sum_v / (f.v1 * f.t0 + v * f.t1) : (f.v1 * f.t0 - v * f.t1) / (h * h * w);
  const double a = std::asinh(w * q);
  const double z_inextensible = l0 * sum_v / sum_t;
  f.x = h * a / w + c * h * l0;
  f.z = z_inextensible + c * (v * l0 + 0.5 * w * l0 * l0);

  const double dt = f.t1 * f.t0;
  f.x_l0 = h / f.t1 + c * h;
  f.x_v = -h * l0 * sum_v / (sum_t * dt);
  f.x_h = (a - h * h * w * q / dt) / w + c * l0;
  f.x_w = (h / w) * (l0 / f.t1 - a / w);
  f.x_c = h * l0;
  f.z_l0 = f.v1 / f.t1 + c * f.v1;
  f.z_v = h * h * q / dt + c * l0;
  f.z_h = -h * l0 * sum_v / (sum_t * dt);
  f.z_w = (f.v1 * l0 / f.t1 - z_inextensible) / w + 0.5 * c * l0 * l0;
  f.z_c = v * l0 + 0.5 * w * l0 * l0;
  return f;
}

}  // namespace

bool evaluate_effect_cable(const EffectCableInput& in, bool with_jacobian, EffectCableOutput& out) {
  const double h = in.f_h, v = in.f_v, w = in.weight_per_length, c = in.compliance, r = in.pulley_radius;
  if (!(h > 0.0) || !(w > 0.0)) return false;

  // Start: the inextensible catenary over the whole span (Eq. 1-4).
  double l0 = evaluate_catenary({h, v, in.span, in.anchor_z, w}, false).arc_length;
  double phi = std::atan2(h, v + w * l0);
  FreeCable f;
  bool converged = false;
  for (int iteration = 0; iteration < 30; ++iteration) {
    f = free_cable(h, v, w, c, l0);
    const double g1 = f.x + r * (1.0 + std::cos(phi)) - in.span;
    const double g2 = phi - std::atan2(h, f.v1);
    const double t1_sq = f.t1 * f.t1;
    // [x_l0, -r sin phi; h w / T1^2, 1] (dl0, dphi) = -(g1, g2)
    const double j11 = f.x_l0, j12 = -r * std::sin(phi), j21 = h * w / t1_sq;
    const double det = j11 - j12 * j21;
    if (!(std::abs(det) > 0.0)) return false;
    const double dl0 = (-g1 + j12 * g2) / det;
    const double dphi = -g2 - j21 * dl0;
    l0 += dl0;
    phi += dphi;
    if (!(l0 > 0.0) || !std::isfinite(phi)) return false;
    if (std::abs(dl0) <= 1e-13 * (1.0 + l0) && std::abs(dphi) <= 1e-13) {
      converged = true;
      break;
    }
  }
  if (!converged) return false;
  f = free_cable(h, v, w, c, l0);

  const double sin_phi = std::sin(phi), cos_phi = std::cos(phi);
  const double wrap = r * (std::numbers::pi - phi);
  const double stretch = 1.0 + c * f.t1;
  out.free_unstretched = l0;
  out.departure_angle = phi;
  out.end_height = in.anchor_z + r * sin_phi - f.z;
  out.payout = l0 + wrap / stretch;
  if (!with_jacobian) return true;

  // Implicit function theorem: G(u, p) = 0 with u = (L0, phi) gives
  // du/dp = -G_u^-1 G_p; each output's total derivative is out_p + out_u du/dp.
  const double t1_sq = f.t1 * f.t1;
  Eigen::Matrix2d g_u;
  g_u << f.x_l0, -r * sin_phi, h * w / t1_sq, 1.0;
  Eigen::Matrix<double, 2, kEffectCableParams> g_p;
  g_p << f.x_h, f.x_v, -1.0, 0.0, f.x_w, f.x_c, 1.0 + cos_phi,  //
      -f.v1 / t1_sq, h / t1_sq, 0.0, 0.0, h * l0 / t1_sq, 0.0, 0.0;
  const Eigen::Matrix<double, 2, kEffectCableParams> du = -g_u.inverse() * g_p;

  // end_height = a_z + r sin phi - Z(h, v, w, c, L0)
  EffectCableRow height_p;
  height_p << -f.z_h, -f.z_v, 0.0, 1.0, -f.z_w, -f.z_c, sin_phi;
  const Eigen::RowVector2d height_u(-f.z_l0, r * cos_phi);
  out.d_end_height = height_p + height_u * du;

  // payout = L0 + W / D with W = r (pi - phi), D = 1 + c T1(h, v, w, L0).
  const double k = -wrap * c / (stretch * stretch);  // d(W / D) / d T1
  EffectCableRow payout_p;
  payout_p << k * h / f.t1, k * f.v1 / f.t1, 0.0, 0.0, k * f.v1 * l0 / f.t1, -wrap * f.t1 / (stretch * stretch),
      (std::numbers::pi - phi) / stretch;
  const Eigen::RowVector2d payout_u(1.0 + k * f.v1 * w / f.t1, -r / stretch);
  out.d_payout = payout_p + payout_u * du;
  return true;
}

}  // namespace cdpr
