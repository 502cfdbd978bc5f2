#pragma once
// The factors of a Problem evaluated into fixed buffers: every factor's
// whitened residuals and its Jacobian blocks with respect to the
// non-constant variables, in two "slots" (so the solver can evaluate a
// candidate point while keeping the current one). Shared by the two linear
// systems the LM builds from a linearisation (NormalEquations: the whole
// J^T J; SchurComplement: J^T J with the per-pose blocks eliminated).
//
// The column layout (where each non-constant variable's tangent block sits
// in the linear system) is the caller's. Everything is sized in the
// constructor, in O(number of factor keys); evaluate() allocates nothing.
// The problem's structure must not change while this object lives.

#include <vector>

#include "solver/nls/problem.h"

namespace cdpr {

class Linearization {
 public:
  static constexpr int kSlots = 2;

  // variable_column[v]: first column of variable v, -1 if it is held constant.
  Linearization(const Problem& problem, std::vector<int> variable_column);

  const Problem& problem() const { return problem_; }
  int variable_column(int v) const { return variable_column_[v]; }
  int factor_count() const { return static_cast<int>(layout_.size()); }

  // Evaluates every factor at `state` (the problem's ambient layout) into
  // `slot`, with Jacobians for the non-constant variables. Returns false at
  // the first factor that refuses or yields a non-finite value, and names it
  // in *failed_factor; *cost is the total 0.5 * sum rho otherwise.
  bool evaluate(const double* state, int slot, double* cost, int* failed_factor);

  // Per factor f (as laid out at construction): residual count, key count,
  // and for its key k the variable, first column (-1 if constant), tangent
  // dim and row-major residual_dim x dim Jacobian in `slot` (null if constant).
  int residual_dim(int f) const { return layout_[f].residual_dim; }
  int key_count(int f) const { return layout_[f].key_count; }
  // Where factor f's keys start in the per-key arrays (f = factor_count(): their total).
  int key_offset(int f) const {
    return f < factor_count() ? layout_[f].key_offset : static_cast<int>(key_variable_.size());
  }
  int key_variable(int f, int k) const { return key_variable_[layout_[f].key_offset + k]; }
  int key_column(int f, int k) const { return key_column_[layout_[f].key_offset + k]; }
  int key_dim(int f, int k) const { return key_dim_[layout_[f].key_offset + k]; }
  // The rows in which key k's Jacobian block can be nonzero (Factor::jacobian_rows).
  RowRange key_rows(int f, int k) const { return key_rows_[layout_[f].key_offset + k]; }
  const double* residuals(int slot, int f) const { return residuals_[slot].data() + layout_[f].residual_offset; }
  const double* jacobian(int slot, int f, int k) const {
    return jacobian_pointers_[slot][layout_[f].key_offset + k];
  }

  // gradient[column of each non-constant key] += J_k' r of factor f in
  // `slot`: that factor's share of J^T r, in the caller's column layout.
  void add_gradient(int slot, int f, double* gradient) const;

 private:
  struct FactorLayout {
    int residual_offset;  // into a slot's residuals
    int key_offset;       // into the per-key arrays
    int residual_dim;
    int key_count;
    int jacobian_offset;  // into a slot's Jacobians: its non-constant keys' blocks, one after another
    int jacobian_size;
  };

  const Problem& problem_;
  std::vector<int> variable_column_;
  std::vector<FactorLayout> layout_;
  std::vector<int> key_variable_, key_column_, key_dim_;  // per factor key
  std::vector<RowRange> key_rows_;
  std::vector<const double*> parameters_;
  std::vector<double> residuals_[kSlots];
  std::vector<double> jacobians_[kSlots];
  std::vector<double*> jacobian_pointers_[kSlots];
};

}  // namespace cdpr
