#pragma once
// One heavy cable with the optional effects that change its shape: elasticity
// (exact elastic catenary, Irvine), a density error (through the weight per
// length) and a swivel pulley at the anchor (docs/DESIGN.md "Swivel pulley").
//
// Frame as in solver/model/catenary.h: the cable's vertical plane, span = horizontal
// distance from the fixed anchor point A to the attachment; (f_h, f_v) is the
// force the cable exerts on the platform at the attachment. Along the
// unstretched arc s from the attachment the tension is T(s) = (f_h, f_v + w s)
// and Hooke's law stretches each element by (1 + |T| / EA). With V1 = f_v + w L0,
// T0 = |(f_h, f_v)|, T1 = |(f_h, V1)|, the free cable of unstretched length L0
// reaches (Irvine's elastic catenary)
//   X = (f_h / w) (asinh(V1 / f_h) - asinh(f_v / f_h)) + c f_h L0        horizontally,
//   Z = (T1 - T0) / w + c (f_v L0 + w L0^2 / 2)                         upwards,
// c = 1 / EA. It ends where it leaves the pulley: at angle phi = atan2(f_h, V1)
// on the pulley circle, r (1 + cos phi) from A towards the attachment and
// r sin phi above A. So (L0, phi) solve
//   X(L0) + r (1 + cos phi) = span,   phi = atan2(f_h, V1(L0)),
// by 2-D Newton from the inextensible catenary without pulley (exact for
// c = r = 0, where the first step already converges). The encoders count the
// unstretched payout L0 + r (pi - phi) / (1 + c T1) (the wrapped cable at the
// pulley-end tension).
//
// Why exact rather than a first-order stretch term: with given end forces the
// stretch also moves the cable end by c f_h L0 horizontally and c (f_v L0 + ...)
// vertically; at EA = 1.5e6 N and 100-300 m cables that is centimetres, above
// the height-consistency sigma of Eq. (15), and the exact form costs only a
// few scalar Newton steps.
//
// Jacobians by the implicit function theorem on (L0, phi). Allocation-free.

#include <Eigen/Core>

namespace cdpr {

struct EffectCableInput {
  double f_h = 0.0;                // [N] > 0
  double f_v = 0.0;                // [N] up positive
  double span = 0.0;               // [m] horizontal anchor-attachment distance
  double anchor_z = 0.0;           // [m] height of A
  double weight_per_length = 0.0;  // [N/m] w > 0 (density effect included by the caller)
  double compliance = 0.0;         // [1/N] c = 1 / EA, 0 = inextensible
  double pulley_radius = 0.0;      // [m] r >= 0, 0 = plain anchor point
};

// Column order of the derivative rows.
enum EffectCableParam { kCableFh, kCableFv, kCableSpan, kCableAnchorZ, kCableWeight, kCableCompliance, kCableRadius };
inline constexpr int kEffectCableParams = 7;
using EffectCableRow = Eigen::Matrix<double, 1, kEffectCableParams>;

struct EffectCableOutput {
  double end_height = 0.0;        // [m] height of the attachment the cable reaches
  double payout = 0.0;            // [m] unstretched cable from A to the attachment: what encoders count
  double free_unstretched = 0.0;  // [m] L0
  double departure_angle = 0.0;   // [rad] phi
  EffectCableRow d_end_height = EffectCableRow::Zero();
  EffectCableRow d_payout = EffectCableRow::Zero();
};

// False when the cable cannot be evaluated (f_h <= 0, w <= 0, or Newton not
// converging / leaving L0 > 0). Derivative rows only when `with_jacobian`.
bool evaluate_effect_cable(const EffectCableInput& in, bool with_jacobian, EffectCableOutput& out);

}  // namespace cdpr
