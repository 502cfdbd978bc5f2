#pragma once
// The Gauss-Newton normal equations J^T J dx = -J^T r of a Problem in a fixed
// sparsity pattern. Everything is sized in the constructor: the column
// layout of the non-constant variables, the block pattern of J^T J (upper
// triangle, compressed sparse columns), the map from each factor's pair of
// variables to value positions, and residual/Jacobian scratch for two
// linearisations ("slots", so the solver can evaluate a candidate point
// while keeping the current one; solver/nls/linearization.h). Construction is
// O(nonzeros); evaluate() and accumulate() allocate nothing. The problem's
// structure must not change while this object lives.

#include <vector>

#include "solver/nls/linearization.h"
#include "solver/nls/problem.h"

namespace cdpr {

class NormalEquations {
 public:
  static constexpr int kSlots = Linearization::kSlots;

  explicit NormalEquations(const Problem& problem);

  int columns() const { return columns_; }  // tangent dims of all non-constant variables
  // First column of variable v in the linear system, -1 if v is constant.
  int variable_column(int v) const { return linearization_.variable_column(v); }
  const std::vector<int>& column_starts() const { return column_starts_; }
  const std::vector<int>& row_indices() const { return row_indices_; }
  int nonzeros() const { return static_cast<int>(row_indices_.size()); }
  // Value position of the diagonal entry of column c.
  int diagonal(int c) const { return column_starts_[c + 1] - 1; }

  // Evaluates every factor at `state` (the problem's ambient layout) into
  // `slot`, with Jacobians for the non-constant variables. Returns false at
  // the first factor that refuses or yields a non-finite value, and names it
  // in *failed_factor; *cost is the total 0.5 * sum rho otherwise.
  bool evaluate(const double* state, int slot, double* cost, int* failed_factor) {
    return linearization_.evaluate(state, slot, cost, failed_factor);
  }

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

  int columns_ = 0;
  Linearization linearization_;
  std::vector<int> column_starts_, row_indices_;
  std::vector<int> block_begin_;  // per factor, into blocks_ (one past the last factor at the end)
  std::vector<BlockRef> blocks_;
};

}  // namespace cdpr
