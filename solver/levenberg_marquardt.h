#pragma once
// Levenberg-Marquardt over the sparse normal equations of a Problem.
//
// Contract: the constructor fixes the sparsity pattern of J^T J, its
// symbolic Cholesky analysis (SparseCholesky) and every scratch buffer;
// solve() then allocates nothing per iteration (checked by a test that
// counts heap allocations). The problem's structure must not change while
// a solver refers to it; values may.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/problem.h"

namespace cdpr {

struct IterationSummary {
  int iteration = 0;
  double cost = 0.0;           // 0.5 * sum of squared whitened residuals (robustified)
  double cost_change = 0.0;    // of the accepted step, 0 if rejected
  double gradient_max_norm = 0.0;
  double step_norm = 0.0;
  double trust_radius = 0.0;   // 1 / damping
  bool step_accepted = false;
};

struct SolverOptions {
  int max_iterations = 100;
  double function_tolerance = 1e-10;   // |d cost| / cost
  double gradient_tolerance = 1e-10;   // max |g_i|
  double parameter_tolerance = 1e-10;  // |dx| / (|x| + tol)
  double initial_trust_radius = 1e4;
  double max_trust_radius = 1e16;
  double min_trust_radius = 1e-32;
  // Called once per iteration (accepted or not); may be empty.
  std::function<void(const IterationSummary&)> progress;
};

enum class TerminationType {
  kConverged,           // a tolerance was met
  kMaxIterations,       // ran out of iterations; the result is the best point found
  kNotEvaluable,        // the model cannot be evaluated at the initial point
  kLinearSolverFailure, // the factorisation failed even with large damping
  kTrustRegionCollapsed // no step decreased the cost any more
};

struct SolverSummary {
  TerminationType termination = TerminationType::kConverged;
  std::string message;  // human-readable: which tolerance, or what failed and why
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  int successful_steps = 0;
  bool usable() const {
    return termination == TerminationType::kConverged || termination == TerminationType::kMaxIterations;
  }
};

class SparseCholesky;

class LevenbergMarquardt {
 public:
  LevenbergMarquardt(Problem& problem, SolverOptions options);
  ~LevenbergMarquardt();

  SolverSummary solve();

  // Marginal covariance of the given non-constant variables at the current
  // values (inverse of J^T J without damping), in tangent coordinates, in the
  // order given. Empty matrix when J^T J is singular.
  Eigen::MatrixXd covariance(const std::vector<Key>& keys);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cdpr
