#include "solver/nls/levenberg_marquardt.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "solver/linalg/normal_equations.h"
#include "solver/linalg/schur_complement.h"
#include "solver/linalg/sparse_cholesky.h"
#include "solver/nls/linearization.h"
#include "solver/nls/trust_region_strategy.h"

namespace cdpr {
namespace {

// Bounds of the damping's diagonal D (Ceres' LevenbergMarquardtStrategy).
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;

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

// The linear system of one linearisation, J^T J dx = -J^T r, as the loop
// needs it: evaluate the factors into a slot, accumulate J^T J and J^T r,
// factorise J^T J + D / radius (radius = infinity: J^T J itself), solve,
// and dx' D dx / radius for the model decrease. None of it allocates.
class LinearSystem {
 public:
  virtual ~LinearSystem() = default;
  virtual LinearSystemKind kind() const = 0;
  virtual int columns() const = 0;
  virtual int variable_column(int v) const = 0;
  virtual const Linearization& linearization() const = 0;
  virtual bool evaluate(const double* state, int slot, double* cost, int* failed_factor) = 0;
  virtual void accumulate(int slot, double* gradient) = 0;
  virtual FactorizationStatus factorize(double radius, std::string* message) = 0;
  virtual void solve(const double* b, double* x) = 0;
  // As solve() for a b that is zero before column `first`, where only x
  // from `first` on is wanted (a covariance of global variables).
  virtual void solve_tail(int /*first*/, const double* b, double* x) { solve(b, x); }
  virtual double damping_quadratic(const double* x, double radius) = 0;
};

// The whole J^T J in CHOLMOD, AMD-ordered: any problem.
class FullSystem final : public LinearSystem {
 public:
  FullSystem(std::unique_ptr<Linearization> linearization, const EliminationOrder& order)
      : linearization_(std::move(linearization)),
        equations_(linearization_->jacobian(), order),
        jtj_(equations_.nonzeros()),
        damped_(equations_.nonzeros()) {
    if (equations_.columns() > 0) {
      cholesky_ = std::make_unique<SparseCholesky>(equations_.columns(), equations_.column_starts(),
                                                   equations_.row_indices());
    }
  }
  LinearSystemKind kind() const override { return LinearSystemKind::kFull; }
  int columns() const override { return equations_.columns(); }
  int variable_column(int v) const override { return equations_.variable_column(v); }
  const Linearization& linearization() const override { return *linearization_; }
  bool evaluate(const double* state, int slot, double* cost, int* failed_factor) override {
    return linearization_->evaluate(state, slot, cost, failed_factor);
  }
  void accumulate(int slot, double* gradient) override { equations_.accumulate(slot, jtj_.data(), gradient); }
  FactorizationStatus factorize(double radius, std::string* message) override {
    std::copy(jtj_.begin(), jtj_.end(), damped_.begin());
    for (int c = 0; c < equations_.columns(); ++c) {
      const int d = equations_.diagonal(c);
      damped_[d] += std::clamp(jtj_[d], kMinDiagonal, kMaxDiagonal) / radius;
    }
    return cholesky_->factorize(damped_.data(), message);
  }
  void solve(const double* b, double* x) override { cholesky_->solve(b, x); }
  double damping_quadratic(const double* x, double radius) override {
    double sum = 0.0;
    for (int c = 0; c < equations_.columns(); ++c) {
      sum += std::clamp(jtj_[equations_.diagonal(c)], kMinDiagonal, kMaxDiagonal) * x[c] * x[c];
    }
    return sum / radius;
  }

 private:
  std::unique_ptr<Linearization> linearization_;
  NormalEquations equations_;
  std::unique_ptr<SparseCholesky> cholesky_;
  std::vector<double> jtj_, damped_;
};

// Per-pose blocks eliminated first, dense Cholesky of the reduced system over the
// global variables (solver/linalg/schur_complement.h): calibration problems.
class ReducedSystem final : public LinearSystem {
 public:
  ReducedSystem(std::unique_ptr<Linearization> linearization, std::unique_ptr<SchurComplement> schur)
      : linearization_(std::move(linearization)), schur_(std::move(schur)) {}
  LinearSystemKind kind() const override { return LinearSystemKind::kPosesEliminated; }
  int columns() const override { return schur_->columns(); }
  int variable_column(int v) const override { return schur_->variable_column(v); }
  const Linearization& linearization() const override { return *linearization_; }
  bool evaluate(const double* state, int slot, double* cost, int* failed_factor) override {
    return linearization_->evaluate(state, slot, cost, failed_factor);
  }
  void accumulate(int slot, double* gradient) override { schur_->accumulate(slot, gradient); }
  FactorizationStatus factorize(double radius, std::string* message) override {
    return schur_->factorize(radius, kMinDiagonal, kMaxDiagonal, message);
  }
  void solve(const double* b, double* x) override { schur_->solve(b, x); }
  // Global columns alone need the reduced system alone: b's pose part is
  // zero, so eliminating it changes nothing, and the poses' back
  // substitution is not wanted.
  void solve_tail(int first, const double* b, double* x) override {
    if (first < schur_->local_columns()) return schur_->solve(b, x);
    schur_->solve_global(b + schur_->local_columns(), x + schur_->local_columns());
  }
  double damping_quadratic(const double* x, double radius) override {
    return schur_->damping_quadratic(x, radius, kMinDiagonal, kMaxDiagonal);
  }

 private:
  std::unique_ptr<Linearization> linearization_;  // read by schur_
  std::unique_ptr<SchurComplement> schur_;
};

// The system for a problem: reduced when its structure allows (the
// elimination order the problem gives), else the whole J^T J (with no
// columns when every variable is constant).
std::unique_ptr<LinearSystem> make_system(const Problem& problem, bool eliminate_poses) {
  auto linearization = std::make_unique<Linearization>(problem);
  const EliminationOrder order = problem.elimination_order();
  if (std::unique_ptr<SchurComplement> schur =
          eliminate_poses ? SchurComplement::create(linearization->jacobian(), order) : nullptr) {
    return std::make_unique<ReducedSystem>(std::move(linearization), std::move(schur));
  }
  return std::make_unique<FullSystem>(std::move(linearization), order);
}

}  // namespace

struct LevenbergMarquardt::Impl {
  Problem& problem;
  SolverOptions options;
  std::unique_ptr<LinearSystem> system;
  std::vector<double> gradient, step, rhs, candidate;
  // Per variable: its first column, -1 if constant (the system's, asked
  // once: a virtual call inside the per-iteration loops kept their sums in
  // memory).
  std::vector<int> column_of;
  int slot = 0;  // linearisation slot of the current point
  // Where the factors were last evaluated into `slot` (by solve() or
  // covariance()), and the cost there; `linearized` is false before.
  bool linearized = false;
  double linearized_cost = 0.0;
  std::vector<double> linearized_state;
  bool reuse_next = false;  // reuse_last_linearization() was called

  Impl(Problem& p, SolverOptions o)
      : problem(p), options(std::move(o)), system(make_system(p, options.eliminate_poses)) {
    const int n = system->columns();
    gradient.assign(n, 0.0);
    step.assign(n, 0.0);
    rhs.assign(n, 0.0);
    candidate.assign(p.state().size(), 0.0);
    linearized_state.assign(p.state().size(), 0.0);
    column_of.reserve(p.variables().size());
    for (std::size_t v = 0; v < p.variables().size(); ++v) {
      column_of.push_back(system->variable_column(static_cast<int>(v)));
    }
  }

  int variable_column(int v) const { return column_of[v]; }
  int columns() const { return static_cast<int>(gradient.size()); }

  // Norm of the ambient values of the non-constant variables (Ceres' |x|).
  double free_state_norm() const {
    double s = 0.0;
    const auto& variables = problem.variables();
    for (std::size_t v = 0; v < variables.size(); ++v) {
      if (variable_column(static_cast<int>(v)) < 0) continue;
      for (int i = 0; i < variables[v].ambient_dim; ++i) {
        const double x = problem.state()[variables[v].ambient_offset + i];
        s += x * x;
      }
    }
    return std::sqrt(s);
  }

  // candidate = state boxplus step
  void make_candidate() {
    std::copy(problem.state().begin(), problem.state().end(), candidate.begin());
    const auto& variables = problem.variables();
    for (std::size_t v = 0; v < variables.size(); ++v) {
      const int column = variable_column(static_cast<int>(v));
      if (column >= 0) problem.retract(static_cast<int>(v), step.data() + column, candidate.data());
    }
  }

  // Whether the caller vouched for the linearisation in `slot` and it is
  // of the current values, bit for bit; the vouching is used up.
  bool take_last_linearization() {
    const bool reuse = reuse_next && linearized && problem.state().size() == linearized_state.size() &&
                       std::memcmp(problem.state().data(), linearized_state.data(),
                                   linearized_state.size() * sizeof(double)) == 0;
    reuse_next = false;
    return reuse;
  }
  void note_linearized(double cost) {
    linearized = true;
    linearized_cost = cost;
    std::copy(problem.state().begin(), problem.state().end(), linearized_state.begin());
  }
  // Evaluates the factors at the current values into `slot` and accumulates
  // J^T J and the gradient, unless the last linearisation may be taken.
  bool linearize(double* cost, int* failed) {
    if (take_last_linearization()) {
      *cost = linearized_cost;
      return true;
    }
    linearized = false;
    if (!system->evaluate(problem.state().data(), slot, cost, failed)) return false;
    system->accumulate(slot, gradient.data());
    note_linearized(*cost);
    return true;
  }

  // The steps of solve(), in the order they run; all but not_evaluable()
  // and summarize(), which run outside the loop, allocation-free.
  enum class Stop { kNone, kGradient, kFunction, kParameter, kCollapsed, kFatal, kNoVariables };
  // Where the loop stands between its steps.
  struct Iterate {
    double cost = 0.0;
    double last_relative_decrease = 0.0;  // |d cost| / cost of the last candidate judged
    double last_step_norm = 0.0;          // |dx| of a step below parameter_tolerance
    int successful_steps = 0;
  };
  SolverSummary not_evaluable(int failed) const;
  Stop iterate(TrustRegionStrategy& strategy, Iterate& at, IterationSummary& it);
  FactorizationStatus solve_damped_system(double radius, double* step_norm);
  bool step_is_negligible(double step_norm) const;
  double predicted_decrease(double radius) const;
  double evaluate_candidate(double predicted);
  void accept_candidate(double new_cost, Iterate& at, IterationSummary& it);
  Stop convergence_test(bool accepted, double old_cost, double new_cost, Iterate& at) const;
  SolverSummary summarize(Stop stop, int iterations, const Iterate& at, const TrustRegionStrategy& strategy,
                          SolverSummary summary);

  SolverSummary solve();
};

SolverSummary LevenbergMarquardt::Impl::solve() {
  if (problem.state().size() != candidate.size()) die("the problem's structure changed after the solver was built");
  Iterate at;
  int failed = -1;
  if (!linearize(&at.cost, &failed)) return not_evaluable(failed);
  SolverSummary summary;
  summary.initial_cost = at.cost;

  IterationSummary it;
  it.cost = at.cost;
  it.gradient_max_norm = max_abs(gradient);
  it.trust_radius = options.initial_trust_radius;
  if (options.progress) options.progress(it);

  // From here to summarize() is the hot path: no allocation
  // (tests/solver/nls/lm_allocation_test.cc counts them); messages are
  // composed afterwards from the numbers.
  Stop stop = Stop::kNone;
  if (system->columns() == 0) stop = Stop::kNoVariables;
  else if (it.gradient_max_norm <= options.gradient_tolerance) stop = Stop::kGradient;
  TrustRegionStrategy strategy({options.initial_trust_radius, options.max_trust_radius, options.min_trust_radius});
  int iteration = 0;
  while (stop == Stop::kNone && iteration < options.max_iterations) {
    it = IterationSummary{};
    it.iteration = ++iteration;
    stop = iterate(strategy, at, it);
    if (stop == Stop::kFatal) break;
    if (options.progress) options.progress(it);
  }
  // `slot` holds the factors at the values the loop leaves.
  note_linearized(at.cost);
  return summarize(stop, iteration, at, strategy, summary);
}

// One iteration: solve the damped system, evaluate the candidate, accept
// or refuse it (the strategy updates the radius), test for convergence.
LevenbergMarquardt::Impl::Stop LevenbergMarquardt::Impl::iterate(TrustRegionStrategy& strategy, Iterate& at,
                                                                 IterationSummary& it) {
  const double radius = strategy.radius();
  const FactorizationStatus status = solve_damped_system(radius, &it.step_norm);
  if (status == FactorizationStatus::kFatal) return Stop::kFatal;
  bool accepted = false;
  Stop stop = Stop::kNone;
  if (status != FactorizationStatus::kSuccess) {
    strategy.reject_step();  // not positive definite: raise the damping
  } else if (step_is_negligible(it.step_norm)) {
    at.last_step_norm = it.step_norm;
    stop = Stop::kParameter;
  } else {
    const double predicted = predicted_decrease(radius);
    const double old_cost = at.cost;
    const double new_cost = evaluate_candidate(predicted);
    // Not evaluable, no model decrease or too small a gain: the strategy
    // shrinks the trust region (raises the damping).
    accepted = strategy.judge_step(old_cost, new_cost, predicted);
    if (accepted) accept_candidate(new_cost, at, it);
    stop = convergence_test(accepted, old_cost, new_cost, at);
  }
  if (stop == Stop::kNone && !accepted && strategy.collapsed()) stop = Stop::kCollapsed;
  it.cost = at.cost;
  it.gradient_max_norm = max_abs(gradient);
  it.trust_radius = strategy.radius();
  it.step_accepted = accepted;
  if (accepted && stop == Stop::kNone && it.gradient_max_norm <= options.gradient_tolerance) stop = Stop::kGradient;
  return stop;
}

// (J^T J + D / radius) dx = -g into `step`; its norm when solved.
FactorizationStatus LevenbergMarquardt::Impl::solve_damped_system(double radius, double* step_norm) {
  const FactorizationStatus status = system->factorize(radius, nullptr);
  if (status != FactorizationStatus::kSuccess) return status;
  for (int c = 0; c < columns(); ++c) rhs[c] = -gradient[c];
  system->solve(rhs.data(), step.data());
  *step_norm = norm(step);
  return status;
}

bool LevenbergMarquardt::Impl::step_is_negligible(double step_norm) const {
  return step_norm <= (free_state_norm() + options.parameter_tolerance) * options.parameter_tolerance;
}

// Predicted decrease of the undamped model, -(g'dx + 0.5 dx'J'J dx), is
// 0.5 (dx'D dx / radius - g'dx) for the dx that solves
// (J'J + D / radius) dx = -g (Madsen, Nielsen, Tingleff, "Methods for
// non-linear least squares problems", 2004, Eq. 3.9b): O(columns) instead
// of a product with J'J.
double LevenbergMarquardt::Impl::predicted_decrease(double radius) const {
  double g_dx = 0.0;
  for (int c = 0; c < columns(); ++c) g_dx += gradient[c] * step[c];
  return 0.5 * (system->damping_quadratic(step.data(), radius) - g_dx);
}

// The cost at state boxplus step, evaluated into the other slot; NaN when
// a factor cannot be evaluated there or the model predicts no decrease.
double LevenbergMarquardt::Impl::evaluate_candidate(double predicted) {
  double new_cost = std::numeric_limits<double>::quiet_NaN();
  if (!(predicted > 0.0)) return new_cost;
  make_candidate();
  int failed = -1;
  if (!system->evaluate(candidate.data(), 1 - slot, &new_cost, &failed)) {
    new_cost = std::numeric_limits<double>::quiet_NaN();
  }
  return new_cost;
}

// The candidate becomes the state; its slot and gradient the current ones.
void LevenbergMarquardt::Impl::accept_candidate(double new_cost, Iterate& at, IterationSummary& it) {
  std::copy(candidate.begin(), candidate.end(), problem.state().begin());
  slot = 1 - slot;
  system->accumulate(slot, gradient.data());
  it.cost_change = at.cost - new_cost;
  at.cost = new_cost;
  ++at.successful_steps;
}

// After a judged candidate: converged when it changed the cost by no more
// than function_tolerance relative. A refused candidate that changes the
// cost that little means the cost is flat to within it here (at a minimum
// its rounding decides the gain ratio), and shrinking the region would only
// try shorter steps of the same nothing; Ceres ends its solve on such a
// candidate too. NaN (not evaluable) fails the test.
LevenbergMarquardt::Impl::Stop LevenbergMarquardt::Impl::convergence_test(bool accepted, double old_cost,
                                                                          double new_cost, Iterate& at) const {
  const double change = std::abs(old_cost - new_cost);
  if (accepted) {
    at.last_relative_decrease = change / old_cost;
    return at.last_relative_decrease <= options.function_tolerance ? Stop::kFunction : Stop::kNone;
  }
  if (!(change <= options.function_tolerance * old_cost)) return Stop::kNone;
  at.last_relative_decrease = change / old_cost;
  return Stop::kFunction;
}

SolverSummary LevenbergMarquardt::Impl::not_evaluable(int failed) const {
  SolverSummary summary;
  summary.termination = TerminationType::kNotEvaluable;
  const auto keys = problem.factors()[failed]->keys();
  summary.message = "factor " + std::to_string(failed) + " (first variable " +
                    (keys.empty() ? std::string("none") : to_string(keys[0])) +
                    ") cannot be evaluated at the initial point";
  return summary;
}

// The summary of a finished loop: why it stopped, in words and figures.
SolverSummary LevenbergMarquardt::Impl::summarize(Stop stop, int iterations, const Iterate& at,
                                                  const TrustRegionStrategy& strategy, SolverSummary summary) {
  summary.iterations = iterations;
  summary.final_cost = at.cost;
  summary.successful_steps = at.successful_steps;
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
                    at.last_relative_decrease, options.function_tolerance);
      break;
    case Stop::kParameter:
      summary.termination = TerminationType::kConverged;
      std::snprintf(buffer, sizeof buffer, "parameter tolerance reached: |dx| = %.3e", at.last_step_norm);
      break;
    case Stop::kCollapsed:
      summary.termination = TerminationType::kTrustRegionCollapsed;
      std::snprintf(buffer, sizeof buffer, "trust region radius %.3e below %.3e: no step decreases the cost",
                    strategy.radius(), options.min_trust_radius);
      break;
    case Stop::kFatal: {
      summary.termination = TerminationType::kLinearSolverFailure;
      std::string why;
      (void)system->factorize(strategy.radius(), &why);
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

void LevenbergMarquardt::set_max_iterations(int max_iterations) { impl_->options.max_iterations = max_iterations; }

SolverSummary LevenbergMarquardt::solve() { return impl_->solve(); }

void LevenbergMarquardt::reuse_last_linearization() { impl_->reuse_next = true; }

std::span<const double> LevenbergMarquardt::last_residuals(int factor) const {
  if (!impl_->linearized) return {};
  return impl_->system->linearization().jacobian().residual_values(impl_->slot, factor);
}

std::span<const double> LevenbergMarquardt::last_jacobian(int factor, int key) const {
  const BlockJacobian& j = impl_->system->linearization().jacobian();
  const double* block = impl_->linearized ? j.jacobian(impl_->slot, factor, key) : nullptr;
  if (block == nullptr) return {};
  return {block, static_cast<std::size_t>(j.residual_dim(factor)) * j.key_dim(factor, key)};
}

LinearSystemKind LevenbergMarquardt::linear_system() const { return impl_->system->kind(); }

Eigen::MatrixXd LevenbergMarquardt::covariance(const std::vector<Key>& keys) {
  Impl& s = *impl_;
  std::vector<int> columns;  // tangent columns of the requested variables, in order
  for (const Key& key : keys) {
    if (!s.problem.has(key)) die("covariance of unknown variable " + to_string(key));
    const int v = s.problem.variable_index(key);
    const int first = s.variable_column(v);
    if (first < 0) die("covariance of constant variable " + to_string(key));
    for (int d = 0; d < s.problem.variables()[v].tangent_dim; ++d) columns.push_back(first + d);
  }
  int failed = -1;
  double cost = 0.0;
  if (s.system->columns() == 0 || !s.linearize(&cost, &failed)) return {};
  if (s.system->factorize(std::numeric_limits<double>::infinity(), nullptr) != FactorizationStatus::kSuccess) {
    return {};
  }

  const int n = static_cast<int>(columns.size());
  const int first = n > 0 ? *std::min_element(columns.begin(), columns.end()) : 0;
  Eigen::MatrixXd result(n, n);
  std::vector<double> unit(s.system->columns(), 0.0), x(s.system->columns());
  for (int j = 0; j < n; ++j) {
    unit[columns[j]] = 1.0;
    s.system->solve_tail(first, unit.data(), x.data());
    unit[columns[j]] = 0.0;
    for (int i = 0; i < n; ++i) result(i, j) = x[columns[i]];
  }
  return 0.5 * (result + result.transpose());
}

}  // namespace cdpr
