#pragma once
// Robust loss on whitened scalar residuals. Belongs to the factor (docs/STYLE.md):
// the LM loop only sees already-corrected residuals, Jacobians and costs.

#include <cmath>

namespace cdpr {

enum class LossKind {
  kSquared,  // plain least squares
  kHuber,    // convex: quadratic within the width, linear beyond
  kCauchy,   // redescending influence: a gross error's pull fades as 1/r
};

// One loss function: rho(s) of s = r^2, with a width in sigma units.
struct LossFunction {
  LossKind kind = LossKind::kSquared;
  double width = 0.0;

  double cost(double r) const;   // 0.5 * rho(r^2)
  double scale(double r) const;  // sqrt(rho'(r^2))
  // Whether cost(r) is 0.5 * r * r, rounded alike, and scale(r) is 1: the
  // loss leaves r and its Jacobian row as least squares would. Inline: the
  // factors ask it of every reading row at every evaluation.
  bool quadratic_at(double r) const {
    switch (kind) {
      case LossKind::kHuber: return !(width > 0.0) || std::abs(r) <= width;
      case LossKind::kCauchy: return !(width > 0.0);
      case LossKind::kSquared: return true;
    }
    return false;
  }
};

struct Loss {
  // Huber width in sigma units; <= 0 means plain least squares.
  double huber_width = 0.0;
  // When set, the loss is read from here at every evaluation instead:
  // calibrate() changes it between the stages of its robust fit (Huber, then
  // Cauchy, then least squares) without rebuilding the problem. It must
  // outlive every factor that holds this Loss.
  const LossFunction* shared = nullptr;

  // Cost 0.5*rho(r^2) of one whitened residual and the factor sqrt(rho'(r^2))
  // by which that residual and its Jacobian row are scaled for the normal
  // equations (Ceres' corrector without its curvature term: exact for Huber
  // since rho'' <= 0 there; for Cauchy it is iteratively reweighted least
  // squares, whose fixed points are the loss's stationary points).
  double cost(double r) const;
  double scale(double r) const;
  bool quadratic_at(double r) const {
    return shared ? shared->quadratic_at(r) : LossFunction{LossKind::kHuber, huber_width}.quadratic_at(r);
  }
  // Quadratic at every residual: plain least squares, not shared.
  bool least_squares() const { return !shared && !(huber_width > 0.0); }
};

}  // namespace cdpr
