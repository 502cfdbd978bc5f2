#include "solver/linalg/normal_equations.h"

#include <algorithm>
#include <cmath>

namespace cdpr {
namespace {

// The grouped variables first, then the kept ones, each in variable order.
std::vector<int> grouped_first_columns(const BlockJacobian& jacobian, const EliminationOrder& order,
                                       int* columns) {
  const int nv = jacobian.variable_count();
  std::vector<int> variable_column(nv, -1);
  *columns = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int v = 0; v < nv; ++v) {
      if (jacobian.constant(v) || (order.group[v] != EliminationOrder::kKept) != (pass == 0)) continue;
      variable_column[v] = *columns;
      *columns += jacobian.variable_dim(v);
    }
  }
  return variable_column;
}

}  // namespace

NormalEquations::NormalEquations(BlockJacobian& jacobian, const EliminationOrder& order) : jacobian_(jacobian) {
  jacobian.assign_columns(grouped_first_columns(jacobian, order, &columns_));
  const int nv = jacobian_.variable_count();
  const int nf = jacobian_.factor_count();
  auto column_of = [&](int v) { return jacobian_.variable_column(v); };
  auto dim = [&](int v) { return jacobian_.variable_dim(v); };

  // Block rows of each block column (indexed by the column's variable),
  // upper triangle: a row variable's first column <= the column variable's.
  std::vector<std::vector<int>> block_rows(nv);
  for (int v = 0; v < nv; ++v) {
    if (column_of(v) >= 0) block_rows[v].push_back(v);
  }
  for (int f = 0; f < nf; ++f) {
    const int nk = jacobian_.key_count(f);
    for (int a = 0; a < nk; ++a) {
      const int va = jacobian_.key_variable(f, a);
      if (column_of(va) < 0) continue;
      for (int b = 0; b < nk; ++b) {
        const int vb = jacobian_.key_variable(f, b);
        if (column_of(vb) >= 0 && column_of(va) < column_of(vb)) block_rows[vb].push_back(va);
      }
    }
  }
  for (auto& rows : block_rows) {
    std::sort(rows.begin(), rows.end(), [&](int x, int y) { return column_of(x) < column_of(y); });
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  }

  // Scalar pattern, column by column; the diagonal block comes last in each
  // of its columns and is cut at the diagonal.
  std::vector<int> column_variable(columns_);
  std::size_t nonzeros = 0;
  for (int v = 0; v < nv; ++v) {
    for (int d = 0; d < dim(v) && column_of(v) >= 0; ++d) {
      column_variable[column_of(v) + d] = v;
      for (int r : block_rows[v]) nonzeros += r == v ? d + 1 : dim(r);
    }
  }
  row_indices_.reserve(nonzeros);
  column_starts_.assign(columns_ + 1, 0);
  for (int c = 0; c < columns_; ++c) {
    const int v = column_variable[c];
    for (int r : block_rows[v]) {
      const int first = column_of(r);
      const int last = r == v ? c : first + dim(r) - 1;
      for (int row = first; row <= last; ++row) row_indices_.push_back(row);
    }
    column_starts_[c + 1] = static_cast<int>(row_indices_.size());
  }

  // Per-factor block references: each pair of non-constant keys, oriented so
  // the row variable comes first in column order. Where its rows start in
  // the column variable's columns (`within`) is resolved per column
  // variable, so the whole pass is linear in the number of blocks.
  block_begin_.reserve(nf + 1);
  std::vector<int> bucket_start(nv + 1, 0);  // blocks per column variable, then prefix sums
  for (int f = 0; f < nf; ++f) {
    block_begin_.push_back(static_cast<int>(blocks_.size()));
    const int nk = jacobian_.key_count(f);
    for (int a = 0; a < nk; ++a) {
      for (int b = a; b < nk; ++b) {
        int ka = a, kb = b;
        const int va = jacobian_.key_variable(f, ka), vb = jacobian_.key_variable(f, kb);
        if (column_of(va) < 0 || column_of(vb) < 0) continue;
        if (column_of(va) > column_of(vb)) std::swap(ka, kb);
        blocks_.push_back({ka, kb, -1});
        ++bucket_start[jacobian_.key_variable(f, kb) + 1];
      }
    }
  }
  block_begin_.push_back(static_cast<int>(blocks_.size()));
  for (int v = 0; v < nv; ++v) bucket_start[v + 1] += bucket_start[v];
  std::vector<int> bucket(blocks_.size());  // (factor, block) pairs grouped by column variable
  std::vector<int> block_factor(blocks_.size());
  {
    std::vector<int> next(bucket_start.begin(), bucket_start.end() - 1);
    for (int f = 0; f < nf; ++f) {
      for (int b = block_begin_[f]; b < block_begin_[f + 1]; ++b) {
        block_factor[b] = f;
        bucket[next[jacobian_.key_variable(f, blocks_[b].column_key)]++] = b;
      }
    }
  }
  std::vector<int> row_offset(nv, -1);  // within the current column variable's columns
  for (int v = 0; v < nv; ++v) {
    int offset = 0;
    for (int r : block_rows[v]) {
      row_offset[r] = offset;
      offset += dim(r);
    }
    for (int i = bucket_start[v]; i < bucket_start[v + 1]; ++i) {
      BlockRef& block = blocks_[bucket[i]];
      block.within = row_offset[jacobian_.key_variable(block_factor[bucket[i]], block.row_key)];
    }
  }
}

void NormalEquations::accumulate(int slot, double* jtj, double* gradient) const {
  std::fill(jtj, jtj + nonzeros(), 0.0);
  std::fill(gradient, gradient + columns_, 0.0);
  const BlockJacobian& lin = jacobian_;
  for (int f = 0; f < lin.factor_count(); ++f) {
    const int m = lin.residual_dim(f);
    lin.add_gradient(slot, f, gradient);
    for (int b = block_begin_[f]; b < block_begin_[f + 1]; ++b) {
      const BlockRef& block = blocks_[b];
      const int dr = lin.key_dim(f, block.row_key), dc = lin.key_dim(f, block.column_key);
      const double* Jr = lin.jacobian(slot, f, block.row_key);
      const double* Jc = lin.jacobian(slot, f, block.column_key);
      const int first_column = lin.key_column(f, block.column_key);
      const bool diagonal_block = block.row_key == block.column_key;
      for (int cl = 0; cl < dc; ++cl) {
        double* out = jtj + column_starts_[first_column + cl] + block.within;
        const int rows = diagonal_block ? cl + 1 : dr;
        for (int rl = 0; rl < rows; ++rl) {
          double sum = 0.0;
          for (int i = 0; i < m; ++i) sum += Jr[i * dr + rl] * Jc[i * dc + cl];
          out[rl] += sum;
        }
      }
    }
  }
}

}  // namespace cdpr
