#pragma once
// The Gauss-Newton normal equations J^T J dx = -J^T r of a block-sparse
// Jacobian in a fixed sparsity pattern. Everything is sized in the
// constructor: the column layout of the non-constant variables, the block
// pattern of J^T J (upper triangle, compressed sparse columns) and the map
// from each factor's pair of variables to value positions. Construction is
// O(nonzeros); accumulate() allocates nothing. The Jacobian must outlive
// this object and keep its structure.

#include <vector>

#include "solver/linalg/block_jacobian.h"
#include "solver/linalg/elimination_order.h"

namespace cdpr {

class NormalEquations {
 public:
  static constexpr int kSlots = BlockJacobian::kSlots;

  // Assigns the Jacobian's columns: the grouped variables first, then the
  // kept ones, each in variable order. The natural ordering is then
  // arrow-shaped (the sparse Cholesky orders by AMD on top anyway).
  NormalEquations(BlockJacobian& jacobian, const EliminationOrder& order);

  int columns() const { return columns_; }  // tangent dims of all non-constant variables
  // First column of variable v in the linear system, -1 if v is constant.
  int variable_column(int v) const { return jacobian_.variable_column(v); }
  const std::vector<int>& column_starts() const { return column_starts_; }
  const std::vector<int>& row_indices() const { return row_indices_; }
  int nonzeros() const { return static_cast<int>(row_indices_.size()); }
  // Value position of the diagonal entry of column c.
  int diagonal(int c) const { return column_starts_[c + 1] - 1; }

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

  const BlockJacobian& jacobian_;
  int columns_ = 0;
  std::vector<int> column_starts_, row_indices_;
  std::vector<int> block_begin_;  // per factor, into blocks_ (one past the last factor at the end)
  std::vector<BlockRef> blocks_;
};

}  // namespace cdpr
