#include "sim/cable_shooting.h"

#include <cmath>

namespace cdpr::sim {

// Integrand f(T) = T/|T| + T/EA and its Jacobian Df = (I - t t^T)/|T| + I/EA,
// integrated with the same Simpson weights, so the end's derivatives with
// respect to the platform-side force are those of the discrete shot itself.
CableShot shoot_cable(const CableProperties& cable, double h_n, double v_n, double unstretched_m, int segments) {
  const double w = cable.weight_per_length_npm;
  const double compliance = std::isfinite(cable.axial_stiffness_n) ? 1.0 / cable.axial_stiffness_n : 0.0;
  const double half_step = 0.5 * unstretched_m / segments;
  const int nodes = 2 * segments + 1;

  Eigen::Vector2d end = Eigen::Vector2d::Zero();
  Eigen::Vector2d d_h = Eigen::Vector2d::Zero();
  Eigen::Vector2d d_v = Eigen::Vector2d::Zero();
  double tension_integral = 0.0;
  for (int j = 0; j < nodes; ++j) {
    // Composite Simpson over half steps: weights 1, 4, 2, 4, ..., 4, 1.
    const double weight = (j == 0 || j == nodes - 1) ? 1.0 : (j % 2 == 1 ? 4.0 : 2.0);
    const double tz = v_n + w * (j * half_step);
    const double norm = std::hypot(h_n, tz);
    const double tx_unit = h_n / norm;
    const double tz_unit = tz / norm;
    end.x() += weight * (tx_unit + compliance * h_n);
    end.y() += weight * (tz_unit + compliance * tz);
    // Columns of Df: d f / d T_x and d f / d T_z.
    d_h.x() += weight * ((1.0 - tx_unit * tx_unit) / norm + compliance);
    d_h.y() += weight * (-tx_unit * tz_unit / norm);
    d_v.x() += weight * (-tx_unit * tz_unit / norm);
    d_v.y() += weight * ((1.0 - tz_unit * tz_unit) / norm + compliance);
    tension_integral += weight * norm;
  }
  const double scale = half_step / 3.0;

  CableShot shot;
  shot.end = end * scale;
  shot.d_end.col(0) = d_h * scale;
  shot.d_end.col(1) = d_v * scale;
  const Eigen::Vector2d t_end(h_n, v_n + w * unstretched_m);
  const double t_end_norm = t_end.norm();
  shot.d_end.col(2) = t_end / t_end_norm + compliance * t_end;
  shot.stretched_length_m = unstretched_m + compliance * tension_integral * scale;
  shot.end_tension_n = t_end;
  return shot;
}

}  // namespace cdpr::sim
