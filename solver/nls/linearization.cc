#include "solver/nls/linearization.h"

#include <cmath>

#include "solver/linalg/dense_kernels.h"

namespace cdpr {
namespace {

BlockJacobian empty_jacobian(const Problem& problem) {
  std::vector<int> dims;
  std::vector<bool> constant;
  for (const Problem::Variable& v : problem.variables()) {
    dims.push_back(v.tangent_dim);
    constant.push_back(v.constant);
  }
  return BlockJacobian(std::move(dims), std::move(constant));
}

}  // namespace

Linearization::Linearization(const Problem& problem) : problem_(problem), jacobian_(empty_jacobian(problem)) {
  const auto& variables = problem.variables();
  std::size_t key_count = 0;
  for (const auto& factor : problem.factors()) key_count += factor->keys().size();
  jacobian_.reserve(static_cast<int>(problem.factors().size()), static_cast<int>(key_count));
  key_ambient_offset_.reserve(key_count);
  std::vector<int> key_variables;
  std::vector<RowRange> key_rows;
  for (const auto& factor : problem.factors()) {
    const std::span<const Key> keys = factor->keys();
    key_variables.clear();
    key_rows.clear();
    for (std::size_t k = 0; k < keys.size(); ++k) {
      const int v = problem.variable_index(keys[k]);
      key_variables.push_back(v);
      key_rows.push_back(factor->jacobian_rows(static_cast<int>(k)));
      key_ambient_offset_.push_back(variables[v].ambient_offset);
    }
    jacobian_.add_factor(factor->residual_dim(), key_variables, key_rows);
  }
  jacobian_.allocate();
  parameters_.assign(key_ambient_offset_.size(), nullptr);
}

bool Linearization::evaluate(const double* state, int slot, double* cost, int* failed_factor) {
  const auto& factors = problem_.factors();
  for (std::size_t k = 0; k < key_ambient_offset_.size(); ++k) parameters_[k] = state + key_ambient_offset_[k];
  double total = 0.0;
  for (std::size_t fi = 0; fi < factors.size(); ++fi) {
    const int f = static_cast<int>(fi);
    double factor_cost = 0.0;
    if (!factors[fi]->evaluate(parameters_.data() + jacobian_.key_offset(f), jacobian_.residuals(slot, f),
                               jacobian_.jacobian_blocks(slot, f), &factor_cost) ||
        !std::isfinite(factor_cost)) {
      *failed_factor = f;
      return false;
    }
    total += factor_cost;
  }
  // Every value at once (one pass over two buffers, cheaper than one call
  // per block); only when something is not finite, which factor it was.
  const BlockJacobian& j = jacobian_;
  if (!all_finite(j.residual_values(slot).data(), j.residual_values(slot).size()) ||
      !all_finite(j.jacobian_values(slot).data(), j.jacobian_values(slot).size())) {
    for (int f = 0; f < j.factor_count(); ++f) {
      if (!all_finite(j.residual_values(slot, f).data(), j.residual_values(slot, f).size()) ||
          !all_finite(j.jacobian_values(slot, f).data(), j.jacobian_values(slot, f).size())) {
        *failed_factor = f;
        return false;
      }
    }
  }
  *cost = total;
  return true;
}

}  // namespace cdpr
