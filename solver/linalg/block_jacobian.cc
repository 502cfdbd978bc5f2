#include "solver/linalg/block_jacobian.h"

#include <cstdio>
#include <cstdlib>
#include <utility>

namespace cdpr {

BlockJacobian::BlockJacobian(std::vector<int> variable_dim, std::vector<bool> constant)
    : variable_dim_(std::move(variable_dim)), constant_(std::move(constant)),
      variable_column_(variable_dim_.size(), -1) {}

void BlockJacobian::reserve(int factors, int keys) {
  layout_.reserve(factors);
  key_variable_.reserve(keys);
  key_column_.reserve(keys);
  key_dim_.reserve(keys);
  key_rows_.reserve(keys);
  key_jacobian_offset_.reserve(keys);
}

void BlockJacobian::add_factor(int residual_dim, std::span<const int> variables, std::span<const RowRange> rows) {
  FactorLayout f;
  f.residual_offset = residual_total_;
  f.key_offset = static_cast<int>(key_variable_.size());
  f.residual_dim = residual_dim;
  f.key_count = static_cast<int>(variables.size());
  f.jacobian_offset = jacobian_total_;
  for (std::size_t k = 0; k < variables.size(); ++k) {
    const int v = variables[k];
    key_variable_.push_back(v);
    key_column_.push_back(-1);
    key_dim_.push_back(variable_dim_[v]);
    key_rows_.push_back(rows[k]);
    key_jacobian_offset_.push_back(constant_[v] ? -1 : jacobian_total_);
    if (!constant_[v]) jacobian_total_ += residual_dim * variable_dim_[v];
  }
  f.jacobian_size = jacobian_total_ - f.jacobian_offset;
  layout_.push_back(f);
  residual_total_ += residual_dim;
}

void BlockJacobian::allocate() {
  for (int s = 0; s < kSlots; ++s) {
    residuals_[s].assign(residual_total_, 0.0);
    jacobians_[s].assign(jacobian_total_, 0.0);
    jacobian_pointers_[s].assign(key_variable_.size(), nullptr);
    for (std::size_t k = 0; k < key_variable_.size(); ++k) {
      if (key_jacobian_offset_[k] >= 0) jacobian_pointers_[s][k] = jacobians_[s].data() + key_jacobian_offset_[k];
    }
  }
}

void BlockJacobian::assign_columns(std::vector<int> variable_column) {
  for (std::size_t v = 0; v < variable_column.size(); ++v) {
    if ((variable_column[v] < 0) != constant_[v]) {
      std::fprintf(stderr, "cdpr::BlockJacobian: variable %zu has %s column\n", v,
                   constant_[v] ? "a constant's" : "no");
      std::abort();
    }
  }
  variable_column_ = std::move(variable_column);
  for (std::size_t k = 0; k < key_variable_.size(); ++k) key_column_[k] = variable_column_[key_variable_[k]];
}

void BlockJacobian::add_gradient(int slot, int f, double* gradient) const {
  const int m = residual_dim(f);
  const double* residual = residuals(slot, f);
  for (int k = 0; k < key_count(f); ++k) {
    const int column = key_column(f, k);
    if (column < 0) continue;
    const int d = key_dim(f, k);
    const double* J = jacobian(slot, f, k);
    for (int i = 0; i < m; ++i) {
      for (int c = 0; c < d; ++c) gradient[column + c] += J[i * d + c] * residual[i];
    }
  }
}

}  // namespace cdpr
