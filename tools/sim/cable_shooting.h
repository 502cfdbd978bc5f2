#pragma once
// One heavy, optionally elastic cable integrated numerically along its
// unstretched arc length: the simulator's independent stand-in for the
// finite-element cable of the paper (Sec. V-A), NOT the closed-form catenary
// of Eq. (1)-(4) that the fitting model uses.
//
// Frame: the cable's vertical plane with its origin at the platform
// attachment point; x runs horizontally TOWARDS THE ANCHOR, z is world height
// (up). The cable pulls on the platform with (h_n, v_n): h_n > 0 towards the
// anchor, v_n up positive. At unstretched distance s from the attachment the
// tension vector (along the cable, pointing towards the anchor) is
//   T(s) = (h_n, v_n + w s),   w = g * rho  [N/m],
// (the platform-side force plus the weight of the cable between 0 and s), and
// Hooke's law gives the position: dr/ds = (1 + |T| / EA) T / |T|, with
// EA = +inf for an inextensible cable. Shooting integrates r from s = 0 to
// s = L0 with Simpson's rule on `segments` equal segments (error O((L0/N)^4)).

#include <Eigen/Core>

namespace cdpr::sim {

struct CableProperties {
  double weight_per_length_npm = 0.0;  // w = g * rho [N/m], > 0
  double axial_stiffness_n = 0.0;      // EA [N]; +inf = inextensible
};

struct CableShot {
  Eigen::Vector2d end = Eigen::Vector2d::Zero();  // (x, z) [m] of the end s = L0, from the attachment
  // d end / d (h_n, v_n, L0); the L0 column is the exact ODE derivative dr/ds at L0.
  Eigen::Matrix<double, 2, 3> d_end = Eigen::Matrix<double, 2, 3>::Zero();
  double stretched_length_m = 0.0;  // integral of (1 + |T| / EA) ds: the true arc length
  Eigen::Vector2d end_tension_n = Eigen::Vector2d::Zero();  // T(L0)
};

// Preconditions (checked by the caller): h_n > 0, unstretched_m >= 0,
// segments >= 1, w > 0, EA > 0. Allocation-free; cost ~ 2 * segments square roots.
CableShot shoot_cable(const CableProperties& cable, double h_n, double v_n, double unstretched_m, int segments);

}  // namespace cdpr::sim
