#pragma once
// The factors of a Problem evaluated into a block-sparse Jacobian
// (solver/linalg/block_jacobian.h): every factor's whitened residuals and
// its Jacobian blocks with respect to the non-constant variables, in two
// slots. The linear systems the LM builds from it (NormalEquations: the
// whole J^T J; SchurComplement: J^T J with groups of variables eliminated
// first) read the Jacobian and assign its column layout.
//
// Everything is sized in the constructor, in O(number of factor keys);
// evaluate() allocates nothing. The problem's structure must not change
// while this object lives.

#include <vector>

#include "solver/linalg/block_jacobian.h"
#include "solver/nls/problem.h"

namespace cdpr {

class Linearization {
 public:
  static constexpr int kSlots = BlockJacobian::kSlots;

  explicit Linearization(const Problem& problem);

  const Problem& problem() const { return problem_; }
  BlockJacobian& jacobian() { return jacobian_; }
  const BlockJacobian& jacobian() const { return jacobian_; }

  // Evaluates every factor at `state` (the problem's ambient layout) into
  // `slot`, with Jacobians for the non-constant variables. Returns false at
  // the first factor that refuses or yields a non-finite value, and names it
  // in *failed_factor; *cost is the total 0.5 * sum rho otherwise.
  bool evaluate(const double* state, int slot, double* cost, int* failed_factor);

 private:
  const Problem& problem_;
  BlockJacobian jacobian_;
  std::vector<int> key_ambient_offset_;  // per factor key: its variable's offset into the state
  std::vector<const double*> parameters_;
};

}  // namespace cdpr
