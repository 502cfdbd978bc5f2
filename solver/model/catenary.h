#pragma once
// The heavy inextensible cable of paper Eq. (1)-(4) in its vertical plane.
//
// Frame: x runs horizontally from the pulley exit point (x = 0) towards the
// attachment point (x = span); z is world height. The cable force at the
// attachment end, as it acts on the platform, has horizontal component
// f_h > 0 (towards the anchor) and vertical component f_v (up positive).

#include <Eigen/Core>

namespace cdpr {

struct CatenaryInput {
  double f_h = 0.0;       // [N] horizontal force, must be > 0
  double f_v = 0.0;       // [N] vertical force on the platform, up positive
  double span = 0.0;      // [m] horizontal distance L_i from anchor to attachment, >= 0
  double anchor_z = 0.0;  // [m] height of the pulley exit point
  double weight_per_length = 0.0;  // [N/m] g_c = g * rho_c, > 0
};

struct CatenaryOutput {
  double end_height = 0.0;  // [m] z(L), Eq. (1) at the attachment
  double arc_length = 0.0;  // [m] l_C, Eq. (4)
  // Partial derivatives with respect to (f_h, f_v, span, anchor_z).
  Eigen::Matrix<double, 1, 4> d_end_height = Eigen::Matrix<double, 1, 4>::Zero();
  Eigen::Matrix<double, 1, 4> d_arc_length = Eigen::Matrix<double, 1, 4>::Zero();
};

// Evaluates Eq. (1)-(4); when `with_jacobian` the d_* rows are filled too.
// Allocation-free. Preconditions (checked by the caller): f_h > 0, g_c > 0.
CatenaryOutput evaluate_catenary(const CatenaryInput& in, bool with_jacobian);

}  // namespace cdpr
