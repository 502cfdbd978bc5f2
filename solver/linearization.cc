#include "solver/linearization.h"

#include <cmath>

namespace cdpr {
namespace {

// x * 0 is 0 for every finite x and NaN for an infinity or NaN, so one
// branch-free sum (which the compiler keeps in two independent halves) tells
// whether any value is not finite; a test per value cost more than the
// factor's own arithmetic on some blocks.
bool all_finite(const double* v, int n) {
  double even = 0.0, odd = 0.0;
  int i = 0;
  for (; i + 2 <= n; i += 2) {
    even += v[i] * 0.0;
    odd += v[i + 1] * 0.0;
  }
  if (i < n) even += v[i] * 0.0;
  return even + odd == 0.0;
}

}  // namespace

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
    for (const Key& key : keys) {
      const int v = problem.variable_index(key);
      key_variable_.push_back(v);
      key_column_.push_back(variable_column_[v]);
      key_dim_.push_back(variables[v].tangent_dim);
      jacobian_offset.push_back(variable_column_[v] >= 0 ? jacobian_total : -1);
      if (variable_column_[v] >= 0) jacobian_total += m * variables[v].tangent_dim;
    }
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
    bool ok = factors[fi]->evaluate(parameters_.data() + f.key_offset, residual, jacobians, &factor_cost) &&
              std::isfinite(factor_cost) && all_finite(residual, f.residual_dim);
    for (int k = 0; ok && k < f.key_count; ++k) {
      if (jacobians[k] != nullptr) ok = all_finite(jacobians[k], f.residual_dim * key_dim_[f.key_offset + k]);
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
