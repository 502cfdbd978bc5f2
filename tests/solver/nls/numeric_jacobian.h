#pragma once
// Central-difference Jacobians of a Factor with respect to the tangent
// perturbations of its variables (pose: d_p then d_theta on the right), to
// check every analytic Jacobian (GTSAM factorTesting.h in spirit). The
// perturbation is the solver's own retraction (retract_ambient), so a
// Jacobian is checked against the steps the solver takes.

#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "solver/nls/factor.h"
#include "solver/nls/problem.h"

namespace cdpr::test {

// One variable's ambient values and whether it is a pose (7 ambient, 6 tangent).
struct TestVariable {
  std::vector<double> ambient;
  bool is_pose = false;
  int tangent_dim() const { return is_pose ? 6 : static_cast<int>(ambient.size()); }
};

// The variable's ambient values moved by h along tangent coordinate j.
inline std::vector<double> perturbed(const TestVariable& v, int j, double h) {
  std::vector<double> out = v.ambient;
  std::vector<double> step(v.tangent_dim(), 0.0);
  step[j] = h;
  retract_ambient(v.is_pose, static_cast<int>(out.size()), step.data(), out.data());
  return out;
}

// The factor evaluated at the variables' values, with its analytic Jacobian
// blocks (row-major, m x tangent_dim each).
struct AnalyticEvaluation {
  std::vector<const double*> parameters;
  std::vector<std::vector<double>> jacobians;
  std::vector<double> residual;
  double cost = 0.0;
  bool ok = false;

  AnalyticEvaluation(const Factor& factor, const std::vector<TestVariable>& vars)
      : jacobians(vars.size()), residual(factor.residual_dim()) {
    const int m = factor.residual_dim();
    std::vector<double*> blocks;
    for (std::size_t b = 0; b < vars.size(); ++b) {
      parameters.push_back(vars[b].ambient.data());
      // NaN, not zero: a factor must write every entry of its blocks (the
      // solver reuses the buffers), which the checks below then see.
      jacobians[b].assign(m * vars[b].tangent_dim(), std::numeric_limits<double>::quiet_NaN());
      blocks.push_back(jacobians[b].data());
    }
    ok = factor.evaluate(parameters.data(), residual.data(), blocks.data(), &cost);
  }

  Eigen::MatrixXd jacobian(std::size_t b) const {
    const int m = static_cast<int>(residual.size());
    const int n = static_cast<int>(jacobians[b].size()) / m;
    return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        jacobians[b].data(), m, n);
  }
};

// Factor::jacobian_rows is a promise the solver builds on: exact zeros
// outside the declared rows of every block.
inline void expect_zero_outside_declared_rows(const Factor& factor, const AnalyticEvaluation& at) {
  const int m = factor.residual_dim();
  for (std::size_t b = 0; b < at.jacobians.size(); ++b) {
    const RowRange rows = factor.jacobian_rows(static_cast<int>(b));
    ASSERT_LE(0, rows.first) << "block " << b;
    ASSERT_LE(rows.first, rows.end) << "block " << b;
    ASSERT_LE(rows.end, m) << "block " << b;
    const Eigen::MatrixXd exact = at.jacobian(b);
    for (int r = 0; r < m; ++r) {
      if (r >= rows.first && r < rows.end) continue;
      for (int c = 0; c < exact.cols(); ++c) {
        EXPECT_EQ(exact(r, c), 0.0) << "block " << b << " row " << r << " column " << c
                                    << " is outside the declared rows [" << rows.first << ", " << rows.end << ")";
      }
    }
  }
}

// Residual and cost with variable b's tangent coordinate j moved by h.
inline bool evaluate_perturbed(const Factor& factor, const std::vector<TestVariable>& vars,
                               std::vector<const double*> parameters, std::size_t b, int j, double h,
                               std::vector<double>& residual, double& cost) {
  const std::vector<double> moved = perturbed(vars[b], j, h);
  parameters[b] = moved.data();
  return factor.evaluate(parameters.data(), residual.data(), nullptr, &cost);
}

// Compares analytic and numeric Jacobians block by block; `tolerance` is
// relative to the largest entry of each block (plus an absolute floor).
inline void expect_jacobians_match(const Factor& factor, const std::vector<TestVariable>& vars, double step,
                                   double tolerance) {
  const AnalyticEvaluation at(factor, vars);
  ASSERT_TRUE(at.ok);
  expect_zero_outside_declared_rows(factor, at);
  const int m = factor.residual_dim();
  std::vector<double> plus(m), minus(m);
  double cost = 0.0;
  for (std::size_t b = 0; b < vars.size(); ++b) {
    const int n = vars[b].tangent_dim();
    Eigen::MatrixXd numeric(m, n);
    for (int j = 0; j < n; ++j) {
      ASSERT_TRUE(evaluate_perturbed(factor, vars, at.parameters, b, j, step, plus, cost));
      ASSERT_TRUE(evaluate_perturbed(factor, vars, at.parameters, b, j, -step, minus, cost));
      for (int r = 0; r < m; ++r) numeric(r, j) = (plus[r] - minus[r]) / (2.0 * step);
    }
    const Eigen::MatrixXd exact = at.jacobian(b);
    const double scale = std::max(1.0, numeric.cwiseAbs().maxCoeff());
    EXPECT_LE((exact - numeric).cwiseAbs().maxCoeff(), tolerance * scale)
        << "block " << b << "\nanalytic:\n" << exact << "\nnumeric:\n" << numeric;
  }
}

// With a robust loss the factor returns Gauss-Newton-corrected residuals and
// Jacobians (Ceres' corrector), not derivatives of each other; what must hold
// is that J^T r is the gradient of the robust cost.
inline void expect_gradient_matches_cost(const Factor& factor, const std::vector<TestVariable>& vars, double step,
                                         double tolerance) {
  const AnalyticEvaluation at(factor, vars);
  ASSERT_TRUE(at.ok);
  expect_zero_outside_declared_rows(factor, at);
  std::vector<double> scratch(factor.residual_dim());
  double cost_plus = 0.0, cost_minus = 0.0;
  const Eigen::Map<const Eigen::VectorXd> r(at.residual.data(), factor.residual_dim());
  for (std::size_t b = 0; b < vars.size(); ++b) {
    const Eigen::VectorXd gradient = at.jacobian(b).transpose() * r;
    for (int j = 0; j < vars[b].tangent_dim(); ++j) {
      ASSERT_TRUE(evaluate_perturbed(factor, vars, at.parameters, b, j, step, scratch, cost_plus));
      ASSERT_TRUE(evaluate_perturbed(factor, vars, at.parameters, b, j, -step, scratch, cost_minus));
      const double numeric = (cost_plus - cost_minus) / (2.0 * step);
      EXPECT_NEAR(gradient(j), numeric, tolerance * std::max(1.0, std::abs(numeric))) << "block " << b << " column " << j;
    }
  }
}

inline TestVariable pose_variable(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  return {{p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()}, true};
}
inline TestVariable vector_variable(std::vector<double> values) { return {std::move(values), false}; }

}  // namespace cdpr::test
