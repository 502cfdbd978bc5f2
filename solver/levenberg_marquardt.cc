#include "solver/levenberg_marquardt.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "solver/normal_equations.h"
#include "solver/sparse_cholesky.h"

namespace cdpr {
namespace {

// Ceres' LevenbergMarquardtStrategy constants.
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "cdpr::LevenbergMarquardt: %s\n", what.c_str());
  std::abort();
}

double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

double norm(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s);
}

// y = A x for the symmetric matrix stored as its upper triangle.
void symmetric_multiply(const NormalEquations& eq, const double* values, const double* x, double* y) {
  std::fill(y, y + eq.columns(), 0.0);
  const auto& starts = eq.column_starts();
  const auto& rows = eq.row_indices();
  for (int c = 0; c < eq.columns(); ++c) {
    for (int k = starts[c]; k < starts[c + 1]; ++k) {
      const int r = rows[k];
      y[r] += values[k] * x[c];
      if (r != c) y[c] += values[k] * x[r];
    }
  }
}

}  // namespace

struct LevenbergMarquardt::Impl {
  Problem& problem;
  SolverOptions options;
  NormalEquations equations;
  std::unique_ptr<SparseCholesky> cholesky;  // null when every variable is constant
  std::vector<double> jtj, damped, gradient, step, jtj_step, candidate;
  int slot = 0;  // linearisation slot of the current point

  Impl(Problem& p, SolverOptions o)
      : problem(p),
        options(std::move(o)),
        equations(p),
        jtj(equations.nonzeros()),
        damped(equations.nonzeros()),
        gradient(equations.columns()),
        step(equations.columns()),
        jtj_step(equations.columns()),
        candidate(p.state().size()) {
    if (equations.columns() > 0) {
      cholesky = std::make_unique<SparseCholesky>(equations.columns(), equations.column_starts(),
                                                  equations.row_indices());
    }
  }

  // Norm of the ambient values of the non-constant variables (Ceres' |x|).
  double free_state_norm() const {
    double s = 0.0;
    const auto& variables = problem.variables();
    for (std::size_t v = 0; v < variables.size(); ++v) {
      if (equations.variable_column(static_cast<int>(v)) < 0) continue;
      for (int i = 0; i < variables[v].ambient_dim; ++i) {
        const double x = problem.state()[variables[v].ambient_offset + i];
        s += x * x;
      }
    }
    return std::sqrt(s);
  }

  void damp(double radius) {
    std::copy(jtj.begin(), jtj.end(), damped.begin());
    for (int c = 0; c < equations.columns(); ++c) {
      const int d = equations.diagonal(c);
      damped[d] += std::clamp(jtj[d], kMinDiagonal, kMaxDiagonal) / radius;
    }
  }

  // candidate = state boxplus step
  void make_candidate() {
    std::copy(problem.state().begin(), problem.state().end(), candidate.begin());
    const auto& variables = problem.variables();
    for (std::size_t v = 0; v < variables.size(); ++v) {
      const int column = equations.variable_column(static_cast<int>(v));
      if (column >= 0) problem.retract(static_cast<int>(v), step.data() + column, candidate.data());
    }
  }

  SolverSummary solve();
};

SolverSummary LevenbergMarquardt::Impl::solve() {
  SolverSummary summary;
  if (problem.state().size() != candidate.size()) die("the problem's structure changed after the solver was built");

  int failed = -1;
  double cost = 0.0;
  if (!equations.evaluate(problem.state().data(), slot, &cost, &failed)) {
    summary.termination = TerminationType::kNotEvaluable;
    const auto keys = problem.factors()[failed]->keys();
    summary.message = "factor " + std::to_string(failed) + " (first variable " +
                      (keys.empty() ? std::string("none") : to_string(keys[0])) +
                      ") cannot be evaluated at the initial point";
    return summary;
  }
  equations.accumulate(slot, jtj.data(), gradient.data());
  summary.initial_cost = summary.final_cost = cost;

  IterationSummary it;
  it.cost = cost;
  it.gradient_max_norm = max_abs(gradient);
  it.trust_radius = options.initial_trust_radius;
  if (options.progress) options.progress(it);

  // Everything below up to the end of the loop is the hot path: no
  // allocation (tests/solver/lm_allocation_test.cc counts them). Messages are
  // composed after the loop from these numbers.
  enum class Stop { kNone, kGradient, kFunction, kParameter, kCollapsed, kFatal, kNoVariables };
  Stop stop = Stop::kNone;
  if (!cholesky) stop = Stop::kNoVariables;
  else if (it.gradient_max_norm <= options.gradient_tolerance) stop = Stop::kGradient;
  double radius = options.initial_trust_radius;
  double nu = 2.0;
  double last_relative_decrease = 0.0, last_step_norm = 0.0;
  int iteration = 0;
  while (stop == Stop::kNone && iteration < options.max_iterations) {
    ++iteration;
    it = IterationSummary{};
    it.iteration = iteration;

    damp(radius);
    const FactorizationStatus status = cholesky->factorize(damped.data(), nullptr);
    if (status == FactorizationStatus::kFatal) {
      stop = Stop::kFatal;
      break;
    }
    bool accepted = false;
    if (status == FactorizationStatus::kSuccess) {
      for (int c = 0; c < equations.columns(); ++c) jtj_step[c] = -gradient[c];
      cholesky->solve(jtj_step.data(), step.data());
      it.step_norm = norm(step);
      const double x_norm = free_state_norm();
      if (it.step_norm <= (x_norm + options.parameter_tolerance) * options.parameter_tolerance) {
        stop = Stop::kParameter;
        last_step_norm = it.step_norm;
      } else {
        // Predicted decrease of the undamped model: -(g.dx + 0.5 dx.JtJ.dx).
        symmetric_multiply(equations, jtj.data(), step.data(), jtj_step.data());
        double g_dx = 0.0, dx_jtj_dx = 0.0;
        for (int c = 0; c < equations.columns(); ++c) {
          g_dx += gradient[c] * step[c];
          dx_jtj_dx += step[c] * jtj_step[c];
        }
        const double predicted = -(g_dx + 0.5 * dx_jtj_dx);
        make_candidate();
        const int other = 1 - slot;
        double new_cost = 0.0;
        if (predicted > 0.0 && equations.evaluate(candidate.data(), other, &new_cost, &failed)) {
          const double actual = cost - new_cost;
          const double rho = actual / predicted;
          if (rho > kMinRelativeDecrease) {
            accepted = true;
            std::copy(candidate.begin(), candidate.end(), problem.state().begin());
            slot = other;
            equations.accumulate(slot, jtj.data(), gradient.data());
            last_relative_decrease = std::abs(actual) / cost;
            it.cost_change = actual;
            cost = new_cost;
            const double t = 2.0 * rho - 1.0;
            radius = std::min(options.max_trust_radius, radius / std::max(1.0 / 3.0, 1.0 - t * t * t));
            nu = 2.0;
            ++summary.successful_steps;
            if (last_relative_decrease <= options.function_tolerance) stop = Stop::kFunction;
          }
        }
      }
    }
    if (!accepted && stop == Stop::kNone) {
      // Not positive definite, no model decrease, not evaluable or too small
      // a gain: shrink the trust region (raise the damping).
      radius /= nu;
      nu *= 2.0;
      if (radius < options.min_trust_radius) stop = Stop::kCollapsed;
    }
    it.cost = cost;
    it.gradient_max_norm = max_abs(gradient);
    it.trust_radius = radius;
    it.step_accepted = accepted;
    if (accepted && stop == Stop::kNone && it.gradient_max_norm <= options.gradient_tolerance) stop = Stop::kGradient;
    if (options.progress) options.progress(it);
  }

  summary.iterations = iteration;
  summary.final_cost = cost;
  char buffer[160];
  switch (stop) {
    case Stop::kNone:
      summary.termination = TerminationType::kMaxIterations;
      std::snprintf(buffer, sizeof buffer, "maximum number of iterations (%d) reached", options.max_iterations);
      break;
    case Stop::kNoVariables:
      summary.termination = TerminationType::kConverged;
      std::snprintf(buffer, sizeof buffer, "every variable is constant: nothing to solve");
      break;
    case Stop::kGradient:
      summary.termination = TerminationType::kConverged;
      std::snprintf(buffer, sizeof buffer, "gradient tolerance reached: max |g| = %.3e <= %.3e",
                    max_abs(gradient), options.gradient_tolerance);
      break;
    case Stop::kFunction:
      summary.termination = TerminationType::kConverged;
      std::snprintf(buffer, sizeof buffer, "function tolerance reached: |d cost| / cost = %.3e <= %.3e",
                    last_relative_decrease, options.function_tolerance);
      break;
    case Stop::kParameter:
      summary.termination = TerminationType::kConverged;
      std::snprintf(buffer, sizeof buffer, "parameter tolerance reached: |dx| = %.3e", last_step_norm);
      break;
    case Stop::kCollapsed:
      summary.termination = TerminationType::kTrustRegionCollapsed;
      std::snprintf(buffer, sizeof buffer, "trust region radius %.3e below %.3e: no step decreases the cost",
                    radius, options.min_trust_radius);
      break;
    case Stop::kFatal: {
      summary.termination = TerminationType::kLinearSolverFailure;
      std::string why;
      (void)cholesky->factorize(damped.data(), &why);
      summary.message = "linear solver failed: " + why;
      return summary;
    }
  }
  summary.message = buffer;
  return summary;
}

LevenbergMarquardt::LevenbergMarquardt(Problem& problem, SolverOptions options)
    : impl_(std::make_unique<Impl>(problem, std::move(options))) {}

LevenbergMarquardt::~LevenbergMarquardt() = default;

SolverSummary LevenbergMarquardt::solve() { return impl_->solve(); }

Eigen::MatrixXd LevenbergMarquardt::covariance(const std::vector<Key>& keys) {
  Impl& s = *impl_;
  std::vector<int> columns;  // tangent columns of the requested variables, in order
  for (const Key& key : keys) {
    if (!s.problem.has(key)) die("covariance of unknown variable " + to_string(key));
    const int v = s.problem.variable_index(key);
    const int first = s.equations.variable_column(v);
    if (first < 0) die("covariance of constant variable " + to_string(key));
    for (int d = 0; d < s.problem.variables()[v].tangent_dim; ++d) columns.push_back(first + d);
  }
  int failed = -1;
  double cost = 0.0;
  if (!s.cholesky || !s.equations.evaluate(s.problem.state().data(), s.slot, &cost, &failed)) return {};
  s.equations.accumulate(s.slot, s.jtj.data(), s.gradient.data());
  if (s.cholesky->factorize(s.jtj.data(), nullptr) != FactorizationStatus::kSuccess) return {};

  const int n = static_cast<int>(columns.size());
  Eigen::MatrixXd result(n, n);
  std::vector<double> unit(s.equations.columns(), 0.0), x(s.equations.columns());
  for (int j = 0; j < n; ++j) {
    unit[columns[j]] = 1.0;
    s.cholesky->solve(unit.data(), x.data());
    unit[columns[j]] = 0.0;
    for (int i = 0; i < n; ++i) result(i, j) = x[columns[i]];
  }
  return 0.5 * (result + result.transpose());
}

}  // namespace cdpr
