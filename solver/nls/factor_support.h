#pragma once
// Small pieces every factor needs: reading a pose from its ambient storage
// and applying the robust loss to whitened residuals and Jacobian rows.

#include <span>

#include "solver/nls/loss.h"
#include "solver/nls/pose.h"

namespace cdpr {

// Ambient pose layout of Problem: x, y, z, qw, qx, qy, qz.
Pose pose_from_parameters(const double* ambient);

// Scales each whitened residual r_j and row j of every non-null Jacobian
// block (row-major, residual_dim x block_dims[b]) by sqrt(rho'(r_j^2)) and
// returns the cost 0.5 * sum rho(r_j^2).
double apply_loss(const Loss& loss, int residual_dim, double* residual, double* const* jacobians,
                  std::span<const int> block_dims);

// As apply_loss on the rows listed in `robust_rows` only; every other row
// costs 0.5 r^2 and is left as it is (model identities such as the
// attachment-height consistency of Eq. (15) are not readings and have no
// gross errors).
double apply_loss_to_rows(const Loss& loss, std::span<const int> robust_rows, int residual_dim, double* residual,
                          double* const* jacobians, std::span<const int> block_dims);

// Zeroes the listed rows of the residual and of every non-null Jacobian
// block: readings left out of a fit.
void zero_rows(std::span<const int> rows, double* residual, double* const* jacobians, std::span<const int> block_dims);

}  // namespace cdpr
