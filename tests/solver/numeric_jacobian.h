#pragma once
// Central-difference Jacobians of a Factor with respect to the tangent
// perturbations of its variables (pose: d_p then d_theta on the right), to
// check every analytic Jacobian (GTSAM factorTesting.h in spirit).

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "solver/factor.h"

namespace cdpr::test {

// One variable's ambient values and whether it is a pose (7 ambient, 6 tangent).
struct TestVariable {
  std::vector<double> ambient;
  bool is_pose = false;
  int tangent_dim() const { return is_pose ? 6 : static_cast<int>(ambient.size()); }
};

inline std::vector<double> perturbed(const TestVariable& v, int j, double h) {
  std::vector<double> out = v.ambient;
  if (!v.is_pose) {
    out[j] += h;
    return out;
  }
  if (j < 3) {
    out[j] += h;
    return out;
  }
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis(j - 3) = 1.0;
  const Eigen::Quaterniond q(v.ambient[3], v.ambient[4], v.ambient[5], v.ambient[6]);
  const Eigen::Quaterniond qp = q * Eigen::Quaterniond(Eigen::AngleAxisd(h, axis));
  out[3] = qp.w(); out[4] = qp.x(); out[5] = qp.y(); out[6] = qp.z();
  return out;
}

// Compares analytic and numeric Jacobians block by block; `tolerance` is
// relative to the largest entry of each block (plus an absolute floor).
inline void expect_jacobians_match(const Factor& factor, const std::vector<TestVariable>& vars, double step,
                                   double tolerance) {
  const int m = factor.residual_dim();
  std::vector<const double*> params;
  for (const auto& v : vars) params.push_back(v.ambient.data());
  std::vector<std::vector<double>> analytic(vars.size());
  std::vector<double*> jac_ptrs;
  for (std::size_t b = 0; b < vars.size(); ++b) {
    analytic[b].assign(m * vars[b].tangent_dim(), 0.0);
    jac_ptrs.push_back(analytic[b].data());
  }
  std::vector<double> residual(m), plus(m), minus(m);
  double cost = 0.0;
  ASSERT_TRUE(factor.evaluate(params.data(), residual.data(), jac_ptrs.data(), &cost));
  for (std::size_t b = 0; b < vars.size(); ++b) {
    const int n = vars[b].tangent_dim();
    Eigen::MatrixXd numeric(m, n);
    for (int j = 0; j < n; ++j) {
      const std::vector<double> vp = perturbed(vars[b], j, step), vm = perturbed(vars[b], j, -step);
      std::vector<const double*> pp = params, pm = params;
      pp[b] = vp.data();
      pm[b] = vm.data();
      ASSERT_TRUE(factor.evaluate(pp.data(), plus.data(), nullptr, &cost));
      ASSERT_TRUE(factor.evaluate(pm.data(), minus.data(), nullptr, &cost));
      for (int r = 0; r < m; ++r) numeric(r, j) = (plus[r] - minus[r]) / (2.0 * step);
    }
    const Eigen::MatrixXd exact = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        analytic[b].data(), m, n);
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
  const int m = factor.residual_dim();
  std::vector<const double*> params;
  for (const auto& v : vars) params.push_back(v.ambient.data());
  std::vector<std::vector<double>> analytic(vars.size());
  std::vector<double*> jac_ptrs;
  for (std::size_t b = 0; b < vars.size(); ++b) {
    analytic[b].assign(m * vars[b].tangent_dim(), 0.0);
    jac_ptrs.push_back(analytic[b].data());
  }
  std::vector<double> residual(m), scratch(m);
  double cost = 0.0, cost_plus = 0.0, cost_minus = 0.0;
  ASSERT_TRUE(factor.evaluate(params.data(), residual.data(), jac_ptrs.data(), &cost));
  const Eigen::Map<const Eigen::VectorXd> r(residual.data(), m);
  for (std::size_t b = 0; b < vars.size(); ++b) {
    const int n = vars[b].tangent_dim();
    const Eigen::MatrixXd J = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        analytic[b].data(), m, n);
    const Eigen::VectorXd gradient = J.transpose() * r;
    for (int j = 0; j < n; ++j) {
      const std::vector<double> vp = perturbed(vars[b], j, step), vm = perturbed(vars[b], j, -step);
      std::vector<const double*> pp = params, pm = params;
      pp[b] = vp.data();
      pm[b] = vm.data();
      ASSERT_TRUE(factor.evaluate(pp.data(), scratch.data(), nullptr, &cost_plus));
      ASSERT_TRUE(factor.evaluate(pm.data(), scratch.data(), nullptr, &cost_minus));
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
