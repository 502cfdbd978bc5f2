#pragma once
// A factor of the calibration graph: whitened (and robustified) residuals
// of the variables it touches, with Jacobians with respect to their tangent
// perturbations.

#include <span>

#include "solver/linalg/row_range.h"
#include "solver/nls/keys.h"

namespace cdpr {

class Factor {
 public:
  virtual ~Factor() = default;

  virtual int residual_dim() const = 0;
  // The variables this factor reads, in the order of `parameters` and `jacobians`.
  virtual std::span<const Key> keys() const = 0;

  // parameters[i]: the ambient storage of keys()[i] (pose: x,y,z,qw,qx,qy,qz;
  // others: their vector). residual: residual_dim() values, whitened and
  // robustified. jacobians: null, or jacobians[i] null or a row-major
  // residual_dim() x tangent_dim(keys()[i]) block. cost: 0.5 * sum rho(r^2).
  // Returns false when the model cannot be evaluated at this point (a cable
  // with no horizontal tension, a singular statics matrix): the LM then treats
  // the step as failed. Must not allocate.
  virtual bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                        double* cost) const = 0;

  // The rows in which the Jacobian block of keys()[k] can be nonzero: a
  // promise that evaluate() writes exact zeros outside them at every point,
  // so a linear system may skip them (most of a pose factor's J^T J is
  // such zeros). All rows unless a factor knows better.
  virtual RowRange jacobian_rows(int /*k*/) const { return {0, residual_dim()}; }
};

}  // namespace cdpr
