#pragma once
// Robust loss on whitened scalar residuals. Belongs to the factor (STYLE.md):
// the LM loop only sees already-corrected residuals, Jacobians and costs.

namespace cdpr {

struct Loss {
  // Huber width in sigma units; <= 0 means plain least squares.
  double huber_width = 0.0;

  // Cost 0.5*rho(r^2) of one whitened residual and the factor sqrt(rho'(r^2))
  // by which that residual and its Jacobian row are scaled for the normal
  // equations (Ceres' corrector; exact for Huber since rho'' <= 0 there).
  double cost(double r) const;
  double scale(double r) const;
};

}  // namespace cdpr
