#include "sim/swivel_pulley.h"

#include <cmath>
#include <numbers>

namespace cdpr::sim {

PulleyDeparture pulley_departure(double radius_m, double end_h_n, double end_v_n) {
  const double phi = std::atan2(end_h_n, end_v_n);
  PulleyDeparture d;
  d.horizontal_m = radius_m * (1.0 + std::cos(phi));
  d.height_m = radius_m * std::sin(phi);
  d.wrapped_arc_m = radius_m * (std::numbers::pi - phi);
  return d;
}

}  // namespace cdpr::sim
