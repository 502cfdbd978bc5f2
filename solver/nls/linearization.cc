#include "solver/nls/linearization.h"

#include <cmath>

#include "solver/linalg/dense_kernels.h"

namespace cdpr {

Linearization::Linearization(const Problem& problem, std::vector<int> variable_column)
    : problem_(problem), variable_column_(std::move(variable_column)) {
  const auto& variables = problem.variables();
  const auto& factors = problem.factors();
  layout_.reserve(factors.size());
  int residual_total = 0, jacobian_total = 0;
  std::vector<int> jacobian_offset;  // per factor key into a slot's Jacobians, -1 if constant
  for (const auto& factor : factors) {
    const std::span<const Key> keys = factor->keys();
    const int m = factor->residual_dim();
    FactorLayout f;
    f.residual_offset = residual_total;
    f.key_offset = static_cast<int>(key_variable_.size());
    f.residual_dim = m;
    f.key_count = static_cast<int>(keys.size());
    f.jacobian_offset = jacobian_total;
    for (std::size_t k = 0; k < keys.size(); ++k) {
      const int v = problem.variable_index(keys[k]);
      key_variable_.push_back(v);
      key_column_.push_back(variable_column_[v]);
      key_dim_.push_back(variables[v].tangent_dim);
      key_rows_.push_back(factor->jacobian_rows(static_cast<int>(k)));
      jacobian_offset.push_back(variable_column_[v] >= 0 ? jacobian_total : -1);
      if (variable_column_[v] >= 0) jacobian_total += m * variables[v].tangent_dim;
    }
    f.jacobian_size = jacobian_total - f.jacobian_offset;
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

bool Linearization::evaluate(const double* state, int slot, double* cost, int* failed_factor) {
  const auto& variables = problem_.variables();
  const auto& factors = problem_.factors();
  for (std::size_t k = 0; k < key_variable_.size(); ++k) {
    parameters_[k] = state + variables[key_variable_[k]].ambient_offset;
  }
  double total = 0.0;
  for (std::size_t fi = 0; fi < factors.size(); ++fi) {
    const FactorLayout& f = layout_[fi];
    double* residual = residuals_[slot].data() + f.residual_offset;
    double* const* jacobians = jacobian_pointers_[slot].data() + f.key_offset;
    double factor_cost = 0.0;
    if (!factors[fi]->evaluate(parameters_.data() + f.key_offset, residual, jacobians, &factor_cost) ||
        !std::isfinite(factor_cost)) {
      *failed_factor = static_cast<int>(fi);
      return false;
    }
    total += factor_cost;
  }
  // Every value at once (one pass over two buffers, cheaper than one call
  // per block); only when something is not finite, which factor it was.
  if (!all_finite(residuals_[slot].data(), residuals_[slot].size()) ||
      !all_finite(jacobians_[slot].data(), jacobians_[slot].size())) {
    for (std::size_t fi = 0; fi < factors.size(); ++fi) {
      const FactorLayout& f = layout_[fi];
      if (!all_finite(residuals_[slot].data() + f.residual_offset, f.residual_dim) ||
          !all_finite(jacobians_[slot].data() + f.jacobian_offset, f.jacobian_size)) {
        *failed_factor = static_cast<int>(fi);
        return false;
      }
    }
  }
  *cost = total;
  return true;
}

void Linearization::add_gradient(int slot, int f, double* gradient) const {
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
