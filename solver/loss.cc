#include "solver/loss.h"

#include <cmath>

namespace cdpr {

// Huber: rho(s) = s for s <= k^2, 2k sqrt(s) - k^2 beyond, with s = r^2.
double Loss::cost(double r) const {
  const double a = std::abs(r);
  if (huber_width <= 0.0 || a <= huber_width) return 0.5 * r * r;
  return huber_width * a - 0.5 * huber_width * huber_width;
}

// sqrt(rho'(s)) = sqrt(k / |r|) beyond the width, so that 0.5 * (scale * r)^2
// has the Huber gradient k * sign(r) at r.
double Loss::scale(double r) const {
  const double a = std::abs(r);
  if (huber_width <= 0.0 || a <= huber_width) return 1.0;
  return std::sqrt(huber_width / a);
}

}  // namespace cdpr
