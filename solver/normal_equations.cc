#include "solver/normal_equations.h"

#include <algorithm>
#include <cmath>

namespace cdpr {
namespace {

// Per-pose variables first, then the global ones that couple all poses: in
// that order the natural ordering is already arrow-shaped (CHOLMOD applies
// AMD on top anyway).
bool is_per_pose(const Key& key) {
  return key.kind == VariableKind::kPose || key.kind == VariableKind::kReferenceForce;
}

bool all_finite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

NormalEquations::NormalEquations(const Problem& problem) : problem_(problem) {
  const auto& variables = problem.variables();
  const auto& factors = problem.factors();
  const int nv = static_cast<int>(variables.size());

  // Column layout.
  variable_column_.assign(nv, -1);
  for (int pass = 0; pass < 2; ++pass) {
    for (int v = 0; v < nv; ++v) {
      if (variables[v].constant || is_per_pose(variables[v].key) != (pass == 0)) continue;
      variable_column_[v] = columns_;
      columns_ += variables[v].tangent_dim;
    }
  }

  // Block rows of each block column (indexed by the column's variable),
  // upper triangle: a row variable's first column <= the column variable's.
  std::vector<std::vector<int>> block_rows(nv);
  for (int v = 0; v < nv; ++v) {
    if (variable_column_[v] >= 0) block_rows[v].push_back(v);
  }
  for (const auto& factor : factors) {
    const std::span<const Key> keys = factor->keys();
    for (const Key& a : keys) {
      for (const Key& b : keys) {
        const int va = problem.variable_index(a), vb = problem.variable_index(b);
        if (variable_column_[va] < 0 || variable_column_[vb] < 0) continue;
        if (variable_column_[va] < variable_column_[vb]) block_rows[vb].push_back(va);
      }
    }
  }
  for (auto& rows : block_rows) {
    std::sort(rows.begin(), rows.end(),
              [&](int x, int y) { return variable_column_[x] < variable_column_[y]; });
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  }

  // Scalar pattern, column by column; the diagonal block comes last in each
  // of its columns and is cut at the diagonal.
  std::vector<int> column_variable(columns_);
  for (int v = 0; v < nv; ++v) {
    for (int d = 0; d < variables[v].tangent_dim && variable_column_[v] >= 0; ++d) {
      column_variable[variable_column_[v] + d] = v;
    }
  }
  column_starts_.assign(columns_ + 1, 0);
  for (int c = 0; c < columns_; ++c) {
    const int v = column_variable[c];
    for (int r : block_rows[v]) {
      const int first = variable_column_[r];
      const int last = r == v ? c : first + variables[r].tangent_dim - 1;
      for (int row = first; row <= last; ++row) row_indices_.push_back(row);
    }
    column_starts_[c + 1] = static_cast<int>(row_indices_.size());
  }
  auto within = [&](int row_variable, int column_variable_index) {
    int offset = 0;
    for (int r : block_rows[column_variable_index]) {
      if (r == row_variable) return offset;
      offset += variables[r].tangent_dim;
    }
    return -1;  // unreachable: every pair was inserted above
  };

  // Per-factor layout, block references and scratch.
  int residual_total = 0, jacobian_total = 0;
  std::vector<int> jacobian_offset;  // per factor key into a slot's Jacobians, -1 if constant
  for (const auto& factor : factors) {
    const std::span<const Key> keys = factor->keys();
    const int m = factor->residual_dim();
    FactorLayout f;
    f.residual_offset = residual_total;
    f.key_offset = static_cast<int>(key_variable_.size());
    f.block_begin = static_cast<int>(blocks_.size());
    for (const Key& key : keys) {
      const int v = problem.variable_index(key);
      key_variable_.push_back(v);
      key_column_.push_back(variable_column_[v]);
      key_dim_.push_back(variables[v].tangent_dim);
      jacobian_offset.push_back(variable_column_[v] >= 0 ? jacobian_total : -1);
      if (variable_column_[v] >= 0) jacobian_total += m * variables[v].tangent_dim;
    }
    const int nk = static_cast<int>(keys.size());
    for (int a = 0; a < nk; ++a) {
      for (int b = a; b < nk; ++b) {
        int ka = a, kb = b;
        const int va = key_variable_[f.key_offset + ka], vb = key_variable_[f.key_offset + kb];
        if (variable_column_[va] < 0 || variable_column_[vb] < 0) continue;
        if (variable_column_[va] > variable_column_[vb]) std::swap(ka, kb);
        const int row_v = key_variable_[f.key_offset + ka], col_v = key_variable_[f.key_offset + kb];
        blocks_.push_back({ka, kb, within(row_v, col_v)});
      }
    }
    f.block_end = static_cast<int>(blocks_.size());
    layout_.push_back(f);
    residual_total += m;
  }
  parameters_.assign(key_variable_.size(), nullptr);
  for (int s = 0; s < kSlots; ++s) {
    residuals_[s].assign(residual_total, 0.0);
    jacobians_[s].assign(jacobian_total, 0.0);
    jacobian_pointers_[s].assign(key_variable_.size(), nullptr);
    for (std::size_t k = 0; k < key_variable_.size(); ++k) {
      if (jacobian_offset[k] >= 0) jacobian_pointers_[s][k] = jacobians_[s].data() + jacobian_offset[k];
    }
  }
}

bool NormalEquations::evaluate(const double* state, int slot, double* cost, int* failed_factor) {
  const auto& variables = problem_.variables();
  const auto& factors = problem_.factors();
  for (std::size_t k = 0; k < key_variable_.size(); ++k) {
    parameters_[k] = state + variables[key_variable_[k]].ambient_offset;
  }
  double total = 0.0;
  for (std::size_t fi = 0; fi < factors.size(); ++fi) {
    const FactorLayout& f = layout_[fi];
    const int m = factors[fi]->residual_dim();
    double* residual = residuals_[slot].data() + f.residual_offset;
    double* const* jacobians = jacobian_pointers_[slot].data() + f.key_offset;
    double factor_cost = 0.0;
    bool ok = factors[fi]->evaluate(parameters_.data() + f.key_offset, residual, jacobians, &factor_cost) &&
              std::isfinite(factor_cost) && all_finite(residual, m);
    const int nk = static_cast<int>(factors[fi]->keys().size());
    for (int k = 0; ok && k < nk; ++k) {
      if (jacobians[k] != nullptr) ok = all_finite(jacobians[k], m * key_dim_[f.key_offset + k]);
    }
    if (!ok) {
      *failed_factor = static_cast<int>(fi);
      return false;
    }
    total += factor_cost;
  }
  *cost = total;
  return true;
}

void NormalEquations::accumulate(int slot, double* jtj, double* gradient) const {
  std::fill(jtj, jtj + nonzeros(), 0.0);
  std::fill(gradient, gradient + columns_, 0.0);
  const auto& factors = problem_.factors();
  for (std::size_t fi = 0; fi < factors.size(); ++fi) {
    const FactorLayout& f = layout_[fi];
    const int m = factors[fi]->residual_dim();
    const double* residual = residuals_[slot].data() + f.residual_offset;
    const double* const* jacobians = jacobian_pointers_[slot].data() + f.key_offset;
    const int nk = static_cast<int>(factors[fi]->keys().size());
    for (int k = 0; k < nk; ++k) {
      const int column = key_column_[f.key_offset + k];
      if (column < 0) continue;
      const int d = key_dim_[f.key_offset + k];
      const double* J = jacobians[k];
      for (int i = 0; i < m; ++i) {
        for (int c = 0; c < d; ++c) gradient[column + c] += J[i * d + c] * residual[i];
      }
    }
    for (int b = f.block_begin; b < f.block_end; ++b) {
      const BlockRef& block = blocks_[b];
      const int dr = key_dim_[f.key_offset + block.row_key], dc = key_dim_[f.key_offset + block.column_key];
      const double* Jr = jacobians[block.row_key];
      const double* Jc = jacobians[block.column_key];
      const int first_column = key_column_[f.key_offset + block.column_key];
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
