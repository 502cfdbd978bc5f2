#pragma once
// A block-sparse Jacobian in fixed buffers, what the linear systems
// (NormalEquations, SchurComplement) are built from. Its rows come in
// residual blocks ("factors"), each reading a few variable blocks ("keys"
// of the factor, each a variable's tangent columns); a factor's Jacobian is
// stored key by key, row-major, for the variables that are not held
// constant. Two "slots" hold two evaluations, so a solver can evaluate a
// candidate point while keeping the current one. Whoever evaluates the
// residuals (nls' Linearization) writes them; nothing here knows what a
// factor or a variable means.
//
// The column layout, where each variable's block sits in the linear system,
// belongs to the linear system that reads the Jacobian: it assigns it
// (assign_columns) from the elimination order the problem gives.
// Everything is sized by add_factor() and allocate(), in O(number of factor
// keys); nothing allocates afterwards.

#include <span>
#include <vector>

#include "solver/linalg/row_range.h"

namespace cdpr {

class BlockJacobian {
 public:
  static constexpr int kSlots = 2;

  // Per variable v: its tangent dimension and whether it is held constant
  // (no column, no Jacobian block).
  BlockJacobian(std::vector<int> variable_dim, std::vector<bool> constant);

  // Room for `factors` factors reading `keys` variables in all, so that
  // appending them does not regrow the per-factor and per-key arrays.
  void reserve(int factors, int keys);
  // Appends a factor of `residual_dim` rows reading `variables`; rows[k]:
  // the rows in which variables[k]'s block can be nonzero.
  void add_factor(int residual_dim, std::span<const int> variables, std::span<const RowRange> rows);
  // Sizes the buffers, after the last add_factor().
  void allocate();
  // variable_column[v]: first column of variable v in the linear system, -1
  // exactly for the constant ones.
  void assign_columns(std::vector<int> variable_column);

  int variable_count() const { return static_cast<int>(variable_dim_.size()); }
  int variable_dim(int v) const { return variable_dim_[v]; }
  bool constant(int v) const { return constant_[v]; }
  int variable_column(int v) const { return variable_column_[v]; }
  int factor_count() const { return static_cast<int>(layout_.size()); }

  // Per factor f: residual count, key count, and for its key k the
  // variable, first column (-1 if constant), tangent dim and row-major
  // residual_dim x dim Jacobian in `slot` (null if constant).
  int residual_dim(int f) const { return layout_[f].residual_dim; }
  int key_count(int f) const { return layout_[f].key_count; }
  // Where factor f's keys start in the per-key arrays (f = factor_count(): their total).
  int key_offset(int f) const {
    return f < factor_count() ? layout_[f].key_offset : static_cast<int>(key_variable_.size());
  }
  int key_variable(int f, int k) const { return key_variable_[layout_[f].key_offset + k]; }
  int key_column(int f, int k) const { return key_column_[layout_[f].key_offset + k]; }
  int key_dim(int f, int k) const { return key_dim_[layout_[f].key_offset + k]; }
  // The rows in which key k's Jacobian block can be nonzero.
  RowRange key_rows(int f, int k) const { return key_rows_[layout_[f].key_offset + k]; }
  const double* residuals(int slot, int f) const { return residuals_[slot].data() + layout_[f].residual_offset; }
  const double* jacobian(int slot, int f, int k) const {
    return jacobian_pointers_[slot][layout_[f].key_offset + k];
  }

  // For the evaluator: where factor f's residuals and Jacobian blocks go in
  // `slot`, and every value of a slot or of one factor in it.
  double* residuals(int slot, int f) { return residuals_[slot].data() + layout_[f].residual_offset; }
  double* const* jacobian_blocks(int slot, int f) { return jacobian_pointers_[slot].data() + layout_[f].key_offset; }
  std::span<const double> residual_values(int slot) const { return residuals_[slot]; }
  std::span<const double> jacobian_values(int slot) const { return jacobians_[slot]; }
  std::span<const double> residual_values(int slot, int f) const {
    return {residuals(slot, f), static_cast<std::size_t>(layout_[f].residual_dim)};
  }
  std::span<const double> jacobian_values(int slot, int f) const {
    return {jacobians_[slot].data() + layout_[f].jacobian_offset, static_cast<std::size_t>(layout_[f].jacobian_size)};
  }

  // gradient[column of each non-constant key] += J_k' r of factor f in
  // `slot`: that factor's share of J^T r, in the assigned column layout.
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

  std::vector<int> variable_dim_;
  std::vector<bool> constant_;
  std::vector<int> variable_column_;
  std::vector<FactorLayout> layout_;
  std::vector<int> key_variable_, key_column_, key_dim_;  // per factor key
  std::vector<RowRange> key_rows_;
  std::vector<int> key_jacobian_offset_;  // per factor key into a slot's Jacobians, -1 if constant
  int residual_total_ = 0, jacobian_total_ = 0;
  std::vector<double> residuals_[kSlots];
  std::vector<double> jacobians_[kSlots];
  std::vector<double*> jacobian_pointers_[kSlots];
};

}  // namespace cdpr
