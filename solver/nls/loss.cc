#include "solver/nls/loss.h"

#include <cmath>

namespace cdpr {

// Huber: rho(s) = s for s <= k^2, 2k sqrt(s) - k^2 beyond.
// Cauchy: rho(s) = k^2 log(1 + s / k^2), rho'(s) = 1 / (1 + s / k^2).
double LossFunction::cost(double r) const {
  const double a = std::abs(r);
  switch (kind) {
    case LossKind::kHuber:
      if (width > 0.0 && a > width) return width * a - 0.5 * width * width;
      break;
    case LossKind::kCauchy:
      if (width > 0.0) return 0.5 * width * width * std::log1p(r * r / (width * width));
      break;
    case LossKind::kSquared:
      break;
  }
  return 0.5 * r * r;
}

// Huber: sqrt(k / |r|) beyond the width, so that 0.5 * (scale * r)^2 has the
// Huber gradient k * sign(r) at r.
double LossFunction::scale(double r) const {
  const double a = std::abs(r);
  switch (kind) {
    case LossKind::kHuber:
      if (width > 0.0 && a > width) return std::sqrt(width / a);
      break;
    case LossKind::kCauchy:
      if (width > 0.0) return 1.0 / std::sqrt(1.0 + r * r / (width * width));
      break;
    case LossKind::kSquared:
      break;
  }
  return 1.0;
}

double Loss::cost(double r) const {
  return shared ? shared->cost(r) : LossFunction{LossKind::kHuber, huber_width}.cost(r);
}

double Loss::scale(double r) const {
  return shared ? shared->scale(r) : LossFunction{LossKind::kHuber, huber_width}.scale(r);
}

}  // namespace cdpr
