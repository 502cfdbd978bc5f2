#pragma once
// The trust-region rule of every nonlinear least-squares solve in the tree
// (Ceres' LevenbergMarquardtStrategy): which trial steps are taken and how
// the region (the inverse of the Levenberg-Marquardt damping) grows or
// shrinks. The caller owns the rest of the loop: it builds and solves the
// damped system (J^T J + D / radius()) dx = -J^T r, evaluates the trial point
// and tests its own convergence criteria.
//
// A step is accepted when its gain ratio
//   rho = (cost - candidate_cost) / predicted_decrease
// exceeds min_relative_decrease, the model predicts a decrease and the
// candidate's cost is a number. Then
//   radius = min(max_radius, radius / max(1/3, 1 - (2 rho - 1)^3)), nu = 2
// (Nielsen's smooth update: a good model widens the region up to threefold,
// a poor one narrows it up to threefold). Otherwise, and for a step that
// could not be computed at all (damped matrix not positive definite),
//   radius = radius / nu, nu = 2 nu
// so that repeated refusals raise the damping ever faster.
//
// Plain value type: no allocation, cheap to copy, safe in allocation-free loops.

namespace cdpr {

struct TrustRegionOptions {
  double initial_radius = 1e4;
  double max_radius = 1e16;
  // Below this the region has collapsed: no step decreases the cost any more.
  double min_radius = 1e-32;
  double min_relative_decrease = 1e-3;
};

class TrustRegionStrategy {
 public:
  explicit TrustRegionStrategy(const TrustRegionOptions& options = TrustRegionOptions{});

  // Back to the initial radius and nu = 2 (the start of a solve).
  void reset();

  // Judges a trial step from the current cost, the candidate's cost (NaN or
  // infinity when it cannot be evaluated) and the decrease the local model
  // predicts, and updates the radius. True: take the step.
  bool judge_step(double cost, double candidate_cost, double predicted_decrease);

  // A step that could not be computed (e.g. the damped matrix is not
  // positive definite): shrinks the region as a refused step does.
  void reject_step();

  double radius() const { return radius_; }
  // 1 / radius: the weight of D in the damped normal matrix.
  double damping() const { return 1.0 / radius_; }
  // Gain ratio of the last judged step (0 before the first, or when the
  // model predicted no decrease).
  double step_quality() const { return step_quality_; }
  bool collapsed() const { return radius_ < options_.min_radius; }
  const TrustRegionOptions& options() const { return options_; }

 private:
  TrustRegionOptions options_;
  double radius_;
  double nu_ = 2.0;
  double step_quality_ = 0.0;
};

}  // namespace cdpr
