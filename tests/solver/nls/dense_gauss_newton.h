#pragma once
// Reference solver for the LM tests: plain Gauss-Newton with a dense J built
// straight from the factors (no pattern, no CHOLMOD, no trust region), on
// the non-constant variables in problem order. Also the dense J^T J for
// covariance checks.

#include <vector>

#include <Eigen/Dense>

#include "solver/nls/problem.h"

namespace cdpr::test {

struct DenseLinearisation {
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd residual;
  std::vector<int> column;  // per variable, -1 if constant
};

inline DenseLinearisation linearise_dense(const Problem& problem) {
  DenseLinearisation out;
  int n = 0, m = 0;
  for (const auto& v : problem.variables()) {
    out.column.push_back(v.constant ? -1 : n);
    if (!v.constant) n += v.tangent_dim;
  }
  for (const auto& f : problem.factors()) m += f->residual_dim();
  out.jacobian = Eigen::MatrixXd::Zero(m, n);
  out.residual = Eigen::VectorXd::Zero(m);
  int row = 0;
  for (const auto& f : problem.factors()) {
    const int fm = f->residual_dim();
    std::vector<const double*> params;
    std::vector<std::vector<double>> blocks;
    std::vector<double*> pointers;
    for (const Key& key : f->keys()) {
      const auto& v = problem.variables()[problem.variable_index(key)];
      params.push_back(problem.state().data() + v.ambient_offset);
      blocks.emplace_back(fm * v.tangent_dim);
    }
    for (auto& b : blocks) pointers.push_back(b.data());
    double cost = 0.0;
    EXPECT_TRUE(f->evaluate(params.data(), out.residual.data() + row, pointers.data(), &cost));
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const int vi = problem.variable_index(f->keys()[k]);
      if (out.column[vi] < 0) continue;
      const int d = problem.variables()[vi].tangent_dim;
      out.jacobian.block(row, out.column[vi], fm, d) +=
          Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(blocks[k].data(), fm, d);
    }
    row += fm;
  }
  return out;
}

// Runs `iterations` full Gauss-Newton steps in place.
inline void dense_gauss_newton(Problem& problem, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    const DenseLinearisation lin = linearise_dense(problem);
    const Eigen::MatrixXd H = lin.jacobian.transpose() * lin.jacobian;
    const Eigen::VectorXd dx = H.ldlt().solve(-lin.jacobian.transpose() * lin.residual);
    for (std::size_t v = 0; v < problem.variables().size(); ++v) {
      if (lin.column[v] >= 0) problem.retract(static_cast<int>(v), dx.data() + lin.column[v]);
    }
  }
}

}  // namespace cdpr::test
