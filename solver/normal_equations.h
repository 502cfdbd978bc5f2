#pragma once
// The Gauss-Newton normal equations J^T J dx = -J^T r of a Problem in a fixed
// sparsity pattern. Everything is sized in the constructor: the column
// layout of the non-constant variables, the block pattern of J^T J (upper
// triangle, compressed sparse columns), the map from each factor's pair of
// variables to value positions, and residual/Jacobian scratch for two
// linearisations ("slots", so the solver can evaluate a candidate point
// while keeping the current one). evaluate() and accumulate() allocate
// nothing. The problem's structure must not change while this object lives.

#include <vector>

#include "solver/problem.h"

namespace cdpr {

class NormalEquations {
 public:
  static constexpr int kSlots = 2;

  explicit NormalEquations(const Problem& problem);

  int columns() const { return columns_; }  // tangent dims of all non-constant variables
  // First column of variable v in the linear system, -1 if v is constant.
  int variable_column(int v) const { return variable_column_[v]; }
  const std::vector<int>& column_starts() const { return column_starts_; }
  const std::vector<int>& row_indices() const { return row_indices_; }
  int nonzeros() const { return static_cast<int>(row_indices_.size()); }
  // Value position of the diagonal entry of column c.
  int diagonal(int c) const { return column_starts_[c + 1] - 1; }

  // Evaluates every factor at `state` (the problem's ambient layout) into
  // `slot`, with Jacobians for the non-constant variables. Returns false at
  // the first factor that refuses or yields a non-finite value, and names it
  // in *failed_factor; *cost is the total 0.5 * sum rho otherwise.
  bool evaluate(const double* state, int slot, double* cost, int* failed_factor);

  // J^T J (values in pattern order, upper triangle) and J^T r of `slot`.
  void accumulate(int slot, double* jtj, double* gradient) const;

 private:
  // One (row variable, column variable) block of one factor: the Jacobians of
  // the factor's keys `row_key` and `column_key` meet at value position
  // column_starts_[c] + within + local row, for each column c of the block.
  struct BlockRef {
    int row_key;
    int column_key;
    int within;
  };
  struct FactorLayout {
    int residual_offset;  // into a slot's residuals
    int key_offset;       // into parameters_, jacobian_pointers_ and key_columns_
    int block_begin, block_end;  // into blocks_
  };

  const Problem& problem_;
  int columns_ = 0;
  std::vector<int> variable_column_;
  std::vector<int> column_starts_, row_indices_;
  std::vector<FactorLayout> layout_;
  std::vector<BlockRef> blocks_;
  std::vector<int> key_variable_;  // per factor key: variable index
  std::vector<int> key_column_;    // per factor key: first column, -1 if constant
  std::vector<int> key_dim_;       // per factor key: tangent dim
  std::vector<const double*> parameters_;
  std::vector<double> residuals_[kSlots];
  std::vector<double> jacobians_[kSlots];
  std::vector<double*> jacobian_pointers_[kSlots];
};

}  // namespace cdpr
