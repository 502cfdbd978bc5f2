#include "solver/catenary.h"

#include <cmath>

namespace cdpr {
namespace {

// sinh(q)/q and (q cosh q - sinh q)/q^2, accurate as q -> 0 where the taut
// (nearly straight) cables of small robots live.
double sinhc(double q) { return std::abs(q) < 1e-4 ? 1.0 + q * q / 6.0 : std::sinh(q) / q; }
double sinhc_slope(double q) {
  return std::abs(q) < 1e-4 ? q / 3.0 + q * q * q / 30.0 : (q * std::cosh(q) - std::sinh(q)) / (q * q);
}

}  // namespace

// With k = g_c / f_h, Eq. (2) gives u1 = k (L + C1) = -asinh(f_v / f_h) and
// u0 = k C1 = u1 - k L; Eq. (1), (3) and (4) then read
//   z(L) - a_z = (cosh u1 - cosh u0) / k = 2 sinh(m) S,
//   l_C        = (sinh u1 - sinh u0) / k = 2 cosh(m) S,
// with m = u1 - k L / 2 and S = sinh(k L / 2) / k = (L / 2) sinhc(k L / 2).
// The product form avoids the cancellation of the differences for taut cables.
CatenaryOutput evaluate_catenary(const CatenaryInput& in, bool with_jacobian) {
  const double k = in.weight_per_length / in.f_h;
  const double slope_ratio = in.f_v / in.f_h;
  const double root = std::sqrt(1.0 + slope_ratio * slope_ratio);
  const double u1 = -std::asinh(slope_ratio);
  const double q = 0.5 * k * in.span;
  const double m = u1 - q;
  const double S = 0.5 * in.span * sinhc(q);
  const double sinh_m = std::sinh(m);
  const double cosh_m = std::cosh(m);

  CatenaryOutput out;
  out.end_height = in.anchor_z + 2.0 * sinh_m * S;
  out.arc_length = 2.0 * cosh_m * S;
  if (!with_jacobian) return out;

  // Derivatives of the intermediates with respect to (f_h, f_v, span).
  const double dk_dfh = -k / in.f_h;
  const double du1_dfh = slope_ratio / (in.f_h * root);
  const double du1_dfv = -1.0 / (in.f_h * root);
  const double dS_dk = 0.25 * in.span * in.span * sinhc_slope(q);
  const double dS_dspan = 0.5 * std::cosh(q);
  const double dq_dk = 0.5 * in.span;
  const double dq_dspan = 0.5 * k;

  const double dm[3] = {du1_dfh - dq_dk * dk_dfh, du1_dfv, -dq_dspan};
  const double dS[3] = {dS_dk * dk_dfh, 0.0, dS_dspan};
  for (int j = 0; j < 3; ++j) {
    out.d_end_height(j) = 2.0 * (cosh_m * S * dm[j] + sinh_m * dS[j]);
    out.d_arc_length(j) = 2.0 * (sinh_m * S * dm[j] + cosh_m * dS[j]);
  }
  out.d_end_height(3) = 1.0;
  out.d_arc_length(3) = 0.0;
  return out;
}

}  // namespace cdpr
