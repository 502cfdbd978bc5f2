#include "solver/model/catenary.h"

#include <cmath>

namespace cdpr {

// With k = g_c / f_h, Eq. (2) gives u1 = k (L + C1) = -asinh(f_v / f_h) and
// u0 = k C1 = u1 - k L; Eq. (1), (3) and (4) then read
//   z(L) - a_z = (cosh u1 - cosh u0) / k = 2 sinh(m) S,
//   l_C        = (sinh u1 - sinh u0) / k = 2 cosh(m) S,
// with m = u1 - k L / 2 and S = sinh(k L / 2) / k = (L / 2) sinhc(k L / 2).
// The product form avoids the cancellation of the differences for taut cables.
// With q = k L / 2, sinh u1 = -f_v / f_h and cosh u1 = sqrt(1 + (f_v / f_h)^2),
// the addition theorems give sinh m and cosh m from sinh q and cosh q, and
// those come from one expm1(q): one transcendental call per cable. (For a
// deeply sagging cable, q > 1/2, the two terms of sinh m grow like e^q and
// may cancel; there m is taken directly.)
CatenaryOutput evaluate_catenary(const CatenaryInput& in, bool with_jacobian) {
  const double k = in.weight_per_length / in.f_h;
  const double slope_ratio = in.f_v / in.f_h;
  const double root = std::sqrt(1.0 + slope_ratio * slope_ratio);
  const double q = 0.5 * k * in.span;
  const double e = std::expm1(q);  // e^q - 1
  const double sinh_q = 0.5 * e * (e + 2.0) / (e + 1.0);
  const double cosh_q = 1.0 + 0.5 * e * e / (e + 1.0);
  const double sinhc_q = std::abs(q) < 1e-4 ? 1.0 + q * q / 6.0 : sinh_q / q;
  const double S = 0.5 * in.span * sinhc_q;
  // m = u1 - q: sinh m = sinh u1 cosh q - cosh u1 sinh q, cosh m = cosh u1 cosh q - sinh u1 sinh q.
  double sinh_m = -slope_ratio * cosh_q - root * sinh_q;
  double cosh_m = root * cosh_q + slope_ratio * sinh_q;
  if (q > 0.5) {
    const double m = -std::asinh(slope_ratio) - q;
    sinh_m = std::sinh(m);
    cosh_m = std::cosh(m);
  }

  CatenaryOutput out;
  out.end_height = in.anchor_z + 2.0 * sinh_m * S;
  out.arc_length = 2.0 * cosh_m * S;
  if (!with_jacobian) return out;

  // Derivatives of the intermediates with respect to (f_h, f_v, span).
  const double sinhc_slope_q = std::abs(q) < 1e-4 ? q / 3.0 + q * q * q / 30.0 : (q * cosh_q - sinh_q) / (q * q);
  const double dk_dfh = -k / in.f_h;
  const double du1_dfh = slope_ratio / (in.f_h * root);
  const double du1_dfv = -1.0 / (in.f_h * root);
  const double dS_dk = 0.25 * in.span * in.span * sinhc_slope_q;
  const double dS_dspan = 0.5 * cosh_q;
  const double dq_dk = 0.5 * in.span;
  const double dq_dspan = 0.5 * k;

  const double dm[3] = {du1_dfh - dq_dk * dk_dfh, du1_dfv, -dq_dspan};
  const double dS[3] = {dS_dk * dk_dfh, 0.0, dS_dspan};
#pragma GCC unroll 3
  for (int j = 0; j < 3; ++j) {
    out.d_end_height(j) = 2.0 * (cosh_m * S * dm[j] + sinh_m * dS[j]);
    out.d_arc_length(j) = 2.0 * (sinh_m * S * dm[j] + cosh_m * dS[j]);
  }
  out.d_end_height(3) = 1.0;
  out.d_arc_length(3) = 0.0;
  return out;
}

}  // namespace cdpr
