#pragma once
// Levenberg-Marquardt over the sparse normal equations of a Problem.
//
// Contract: the constructor fixes the sparsity pattern of J^T J, its
// symbolic Cholesky analysis (SparseCholesky) and every scratch buffer, in
// time linear in the problem's size. When no factor couples two poses' own
// variables (the calibration graph), the per-pose blocks are eliminated
// first and only the small reduced system over the global variables
// (anchors, offsets, model terms) is factorised, densely, so an iteration
// costs O(poses); otherwise CHOLMOD factorises the whole J^T J.
// solve() then allocates nothing per iteration (checked by a test that
// counts heap allocations). The problem's structure must not change while
// a solver refers to it; values may (solve() starts from the current ones).
//
// Each iteration solves (J^T J + D / radius) dx = -J^T r with
// D = diag(J^T J) clamped to [1e-6, 1e32]; a candidate that every factor
// evaluates is judged, and the radius updated, by the TrustRegionStrategy
// (solver/nls/trust_region_strategy.h: accepted when the actual/predicted
// cost reduction exceeds 1e-3). A damped matrix that is not positive
// definite counts as a refused step. The candidate is evaluated on a copy of
// the state, so a rejected step costs no undo. The solve has converged when
// a candidate, accepted or refused, changes the cost by no more than
// function_tolerance relative (as in Ceres), when a step is shorter than
// parameter_tolerance relative, or when the gradient is within
// gradient_tolerance.

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/nls/problem.h"

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
  // Eliminate the per-pose variables first (Schur complement, dense Cholesky
  // of the reduced system over the global ones) when no factor couples two poses;
  // false: always factorise the whole J^T J.
  bool eliminate_poses = true;
  // Called with iteration 0 (the initial point) and then once per iteration,
  // accepted or not; may be empty. It runs inside the allocation-free loop.
  std::function<void(const IterationSummary&)> progress;
};

enum class TerminationType {
  kConverged,           // a tolerance was met
  kMaxIterations,       // ran out of iterations; the result is the best point found
  kNotEvaluable,        // the model cannot be evaluated at the initial point
  kLinearSolverFailure, // the factorisation failed fatally (out of memory, non-finite J^T J)
  kTrustRegionCollapsed // radius < min_trust_radius: no step decreased the cost any more
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

enum class LinearSystemKind {
  kFull,             // the whole J^T J in CHOLMOD (AMD order)
  kPosesEliminated,  // per-pose blocks eliminated, dense Cholesky on the global variables (solver/linalg/schur_complement.h)
};

class LevenbergMarquardt {
 public:
  LevenbergMarquardt(Problem& problem, SolverOptions options);
  ~LevenbergMarquardt();

  SolverSummary solve();
  // The iteration limit of the next solve() calls (calibrate() shares one
  // budget among the stages of its robust fit).
  void set_max_iterations(int max_iterations);

  // solve() and covariance() first evaluate the factors at the current
  // values. A caller that knows the factors would give, bit for bit, what
  // they gave where the last solve() ended (the values unchanged since, and
  // a loss switched since inactive at every residual there) can spare that:
  // the next solve() or covariance() takes that linearisation as it is.
  // The factors are evaluated anyway when the values have changed.
  void reuse_last_linearization();
  // Factor `factor`'s residuals (whitened, after its loss) where the last
  // solve() ended; empty when it could not evaluate its start.
  std::span<const double> last_residuals(int factor) const;
  // The Jacobian block of keys()[key] of factor `factor` there (whitened,
  // after its loss; residual_dim x tangent dim, row-major); empty when the
  // variable is held constant or the start could not be evaluated.
  std::span<const double> last_jacobian(int factor, int key) const;

  // Which linear system the constructor chose for this problem.
  LinearSystemKind linear_system() const;

  // Marginal covariance of the given non-constant variables at the current
  // values (inverse of J^T J without damping), in tangent coordinates, in the
  // order given. Empty matrix when J^T J is singular (not positive definite)
  // or a factor cannot be evaluated. Aborts on an unknown or constant key.
  // Allocates (it is not part of the loop).
  Eigen::MatrixXd covariance(const std::vector<Key>& keys);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cdpr
