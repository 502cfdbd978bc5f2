#pragma once
// Levenberg-Marquardt for small dense least-squares problems: a few unknowns
// and residuals, evaluated by a callback with an analytic Jacobian or by
// central differences of the residuals. The solves of one pose's unknowns
// use it: the start's reference force and heading (model/initial_guess.cc),
// the rest pose at a commanded position (model/static_pose.cc) and the
// leave-one-out refit of a row (calibration/row_attribution.cc).
// LevenbergMarquardt (levenberg_marquardt.h) is its sparse sibling for whole
// factor graphs; both damp and judge their steps the same way (its cost is
// chi2 / 2, which leaves the gain ratio as it is):
//
//   chi2(x) = |r(x)|^2, r whitened by the caller
//   (J^T J + D / radius) dx = -g,  g = J^T r,  D = diag(J^T J) clamped to
//       [min_diagonal, max_diagonal]
//   predicted decrease of chi2: -(2 g^T dx + dx^T J^T J dx)
//   the trial x + dx judged, and the radius updated, by TrustRegionStrategy
//   (trust_region_strategy.h); a damped matrix that is not positive
//   definite counts as a refused step.
//
// Bounds (Euclidean unknowns only): a coordinate whose step would cross its
// bound stops on it, and the others take the damped model's best step with
// it held there (the minimum of the damped quadratic over the free ones).
//
// Stops (DenseDampedStop), before each trial:
//   every |r_i| <= residual_tolerance            kResidualTolerance (a root)
//   max_trials trials made                       kMaxTrials
//   radius below trust_region.min_radius         kTrustRegionCollapsed
// and within a trial, with gain_tolerance * (chi2 + gain_floor) as the bar:
//   the model predicts no more decrease than the bar (rounding would then
//   refuse trial after trial), or an accepted step decreased chi2 by less
//                                                kSmallGain
// and when the callback cannot evaluate the start (kNotEvaluable), or central
// differences next to an accepted point (kJacobianNotEvaluable).
// x is the best point found: the start or the last accepted trial, each of
// which the callback evaluated. Fixed sizes allocate nothing; with
// Eigen::Dynamic the buffers are sized by the callback's first answer.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "solver/nls/trust_region_strategy.h"

namespace cdpr {

struct DenseDampedOptions {
  TrustRegionOptions trust_region;
  int max_trials = 100;
  // Bounds of D, as LevenbergMarquardt's.
  double min_diagonal = 1e-6;
  double max_diagonal = 1e32;
  // The kSmallGain bar is gain_tolerance * (chi2 + gain_floor); 0 stops only
  // where the model predicts no decrease at all.
  double gain_tolerance = 0.0;
  double gain_floor = 0.0;
  // Negative: no residual test.
  double residual_tolerance = -1.0;
  // Central differences: step relative_step * max(1, |x_j|) per coordinate.
  double relative_step = 1e-6;
};

enum class DenseDampedStop {
  kResidualTolerance,     // every |r_i| within residual_tolerance
  kSmallGain,             // the decrease fell below the bar: at the minimum
  kMaxTrials,             // out of trials; x is the best point found
  kTrustRegionCollapsed,  // no step decreases chi2 any more
  kNotEvaluable,          // the start cannot be evaluated (x unchanged)
  kJacobianNotEvaluable,  // central differences failed next to an accepted point (x is that point)
};

struct DenseDampedSummary {
  DenseDampedStop stop = DenseDampedStop::kNotEvaluable;
  int trials = 0;    // trial steps, accepted or refused
  int accepted = 0;  // of which accepted
  double initial_chi2 = std::numeric_limits<double>::quiet_NaN();
  double final_chi2 = std::numeric_limits<double>::quiet_NaN();
  bool converged() const { return stop == DenseDampedStop::kResidualTolerance || stop == DenseDampedStop::kSmallGain; }
  // Why it stopped, one line with the figures.
  std::string message() const;
};

const char* to_string(DenseDampedStop stop);

template <int Rows, int Cols>
class DenseDampedSolver {
 public:
  using Vector = Eigen::Matrix<double, Cols, 1>;
  using Residuals = Eigen::Matrix<double, Rows, 1>;
  using Jacobian = Eigen::Matrix<double, Rows, Cols>;
  using Normal = Eigen::Matrix<double, Cols, Cols>;

  explicit DenseDampedSolver(const DenseDampedOptions& options) : options_(options) {}

  // Bounds of the Euclidean unknowns (minimize, minimize_numeric); an
  // infinite bound is none. The start must lie within them.
  void set_bounds(const Vector& lower, const Vector& upper) {
    lower_ = lower;
    upper_ = upper;
    bounded_ = true;
  }

  // `evaluate(x, residuals, jacobian)`: false where the model is undefined
  // at x; `jacobian` is never null here (asked with every trial: an analytic
  // Jacobian shares the residuals' work).
  template <typename Evaluate>
  DenseDampedSummary minimize(Vector& x, const Evaluate& evaluate) {
    return run(x, evaluate, [](const Vector&, Jacobian&) { return true; }, euclidean());
  }

  // `residuals(x, r)` alone: the Jacobian by central differences, taken only
  // at the start and at accepted points.
  template <typename EvaluateResiduals>
  DenseDampedSummary minimize_numeric(Vector& x, const EvaluateResiduals& residuals) {
    auto trial = [&](const Vector& at, Residuals& r, Jacobian*) { return residuals(at, r); };
    auto differences = [&](const Vector& at, Jacobian& jacobian) {
      Residuals plus, minus;
      for (int j = 0; j < at.size(); ++j) {
        const double h = options_.relative_step * std::max(1.0, std::abs(at(j)));
        Vector moved = at;
        moved(j) = at(j) + h;
        if (!residuals(moved, plus)) return false;
        moved(j) = at(j) - h;
        if (!residuals(moved, minus)) return false;
        if (j == 0) jacobian.resize(plus.size(), at.size());
        jacobian.col(j) = (plus - minus) / (2.0 * h);
      }
      return true;
    };
    return run(x, trial, differences, euclidean());
  }

  // On a manifold: `x` any point type, `evaluate(x, residuals, jacobian)`
  // gives the Jacobian in the tangent at x, `retract(x, step, out)` sets
  // out = x boxplus step (step of the Jacobian's columns). No bounds.
  template <typename Point, typename Evaluate, typename Retract>
  DenseDampedSummary minimize_on_manifold(Point& x, const Evaluate& evaluate, const Retract& retract) {
    return run(x, evaluate, [](const Point&, Jacobian&) { return true; }, retract);
  }

 private:
  auto euclidean() {
    return [this](const Vector& x, const Vector& step, Vector& out) {
      out = x + step;
      if (bounded_) out = out.cwiseMax(lower_).cwiseMin(upper_);
    };
  }

  // The loop. `evaluate_trial(x, r, J*)` gives the residuals at a trial (and
  // the Jacobian when the callback computes it with them);
  // `jacobian_at(x, J)` completes the Jacobian at the start and at accepted
  // points when it does not.
  template <typename Point, typename EvaluateTrial, typename JacobianAt, typename Retract>
  DenseDampedSummary run(Point& x, const EvaluateTrial& evaluate_trial, const JacobianAt& jacobian_at,
                         const Retract& retract) {
    DenseDampedSummary summary;
    if (!evaluate_trial(x, residuals_, &jacobian_)) return summary;
    if (!jacobian_at(x, jacobian_)) return summary;
    double chi2 = residuals_.squaredNorm();
    summary.initial_chi2 = summary.final_chi2 = chi2;
    linearize();
    TrustRegionStrategy strategy(options_.trust_region);
    Point trial = x;
    for (;;) {
      if (options_.residual_tolerance >= 0.0 && residuals_.cwiseAbs().maxCoeff() <= options_.residual_tolerance) {
        return stop(summary, DenseDampedStop::kResidualTolerance);
      }
      if (summary.trials == options_.max_trials) return stop(summary, DenseDampedStop::kMaxTrials);
      if (strategy.collapsed()) return stop(summary, DenseDampedStop::kTrustRegionCollapsed);
      ++summary.trials;
      if (!damped_step(strategy.radius(), x)) {
        strategy.reject_step();
        continue;
      }
      const double predicted = -(2.0 * gradient_.dot(step_) + step_.dot(jtj_ * step_));
      const double bar = options_.gain_tolerance * (chi2 + options_.gain_floor);
      if (!(predicted > bar)) return stop(summary, DenseDampedStop::kSmallGain);
      retract(x, step_, trial);
      const double trial_chi2 = evaluate_trial(trial, trial_residuals_, &trial_jacobian_)
                                    ? trial_residuals_.squaredNorm()
                                    : std::numeric_limits<double>::quiet_NaN();
      if (!strategy.judge_step(chi2, trial_chi2, predicted)) continue;
      const bool small_gain = chi2 - trial_chi2 < bar;
      std::swap(x, trial);
      std::swap(residuals_, trial_residuals_);
      std::swap(jacobian_, trial_jacobian_);
      chi2 = summary.final_chi2 = trial_chi2;
      ++summary.accepted;
      if (small_gain) return stop(summary, DenseDampedStop::kSmallGain);
      if (!jacobian_at(x, jacobian_)) return stop(summary, DenseDampedStop::kJacobianNotEvaluable);
      linearize();
    }
  }

  static DenseDampedSummary stop(DenseDampedSummary& summary, DenseDampedStop why) {
    summary.stop = why;
    return summary;
  }

  // J^T J and g at the current point.
  void linearize() {
    jtj_.noalias() = jacobian_.transpose() * jacobian_;
    gradient_.noalias() = jacobian_.transpose() * residuals_;
  }

  // step_ from the damped system at `radius`, held on the bounds; false
  // when the damped matrix is not positive definite.
  template <typename Point>
  bool damped_step(double radius, const Point& x) {
    const Vector scaling = jtj_.diagonal().cwiseMax(options_.min_diagonal).cwiseMin(options_.max_diagonal) / radius;
    damped_ = jtj_;
    damped_.diagonal() += scaling;
    ldlt_.compute(damped_);
    if (ldlt_.info() != Eigen::Success || !ldlt_.isPositive()) return false;
    step_ = -ldlt_.solve(gradient_);
    if constexpr (std::is_same_v<Point, Vector>) {
      if (bounded_) return hold_on_bounds(x);
    }
    return step_.allFinite();
  }

  // Coordinates whose step crosses a bound stop on it; the others solve
  // the damped system with those held: damped_ff s_f = -(g_f + damped_fb s_b).
  bool hold_on_bounds(const Vector& x) {
    Vector held = Vector::Zero(x.size());
    Eigen::Array<bool, Cols, 1> on_bound = Eigen::Array<bool, Cols, 1>::Constant(x.size(), false);
    for (int i = 0; i < x.size(); ++i) {
      const double target = x(i) + step_(i);
      const double kept = std::clamp(target, lower_(i), upper_(i));
      if (kept == target) continue;
      held(i) = kept - x(i);
      on_bound(i) = true;
    }
    if (!on_bound.any()) return step_.allFinite();
    Vector rhs = -(gradient_ + damped_ * held);
    for (int i = 0; i < x.size(); ++i) {
      if (!on_bound(i)) continue;
      damped_.row(i).setZero();
      damped_.col(i).setZero();
      damped_(i, i) = 1.0;
      rhs(i) = held(i);
    }
    ldlt_.compute(damped_);
    if (ldlt_.info() != Eigen::Success || !ldlt_.isPositive()) return false;
    step_ = ldlt_.solve(rhs);
    return step_.allFinite();
  }

  DenseDampedOptions options_;
  bool bounded_ = false;
  Vector lower_, upper_;
  Residuals residuals_, trial_residuals_;
  Jacobian jacobian_, trial_jacobian_;
  Normal jtj_, damped_;
  Vector gradient_, step_;
  Eigen::LDLT<Normal> ldlt_;
};

}  // namespace cdpr
