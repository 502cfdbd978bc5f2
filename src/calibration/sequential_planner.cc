#include "src/calibration/sequential_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace cdpr::calibration {
namespace {

// The information of the initial set counts as full rank when its smallest
// eigenvalue is at least this fraction of its largest: well above round-off
// of a sum of rank-4 terms, far below what a usable design reaches.
constexpr double kIdentifiableConditioning = 1e-9;

using DesignVector = Eigen::Matrix<double, kDesignParameters, 1>;

bool identifiable(const Robot& robot, const std::vector<Pose>& poses) {
  DesignInformation information = DesignInformation::Zero();
  for (const Pose& pose : poses) information += pose_information(robot, pose);
  const Eigen::SelfAdjointEigenSolver<DesignInformation> eigen(information, Eigen::EigenvaluesOnly);
  const DesignVector values = eigen.eigenvalues();
  return values.maxCoeff() > 0.0 && values.minCoeff() >= kIdentifiableConditioning * values.maxCoeff();
}

// Progress is counted down to half the target sigma, not to the target: the
// straight-cable information predicts a pose's variance reduction more
// optimistically than the re-solved fit then shows, and with the floor at the
// target itself most candidates saturate, the time term then picks short hops
// that gain little, and a looser target took more waypoints than a tight one.
constexpr double kProgressFloor = 0.25;  // of target^2

// Progress towards the targets that `after` makes from `before` (the
// diagonal of covariances): per parameter, log(max(before, f t^2) /
// max(after, f t^2)), f = kProgressFloor. The stop needs every parameter
// below its target, so halving one variance counts the same however far
// above its target it still is. Targets of zero: the plain trace reduction.
double gain(const DesignVector& before, const DesignVector& after, const DesignVector& target_sq) {
  if (target_sq.isZero()) return before.sum() - after.sum();
  double sum = 0.0;
  for (int j = 0; j < kDesignParameters; ++j) {
    const double floor = kProgressFloor * target_sq(j);
    sum += std::log(std::max(before(j), floor) / std::max(after(j), floor));
  }
  return sum;
}

// The fit's covariance of anchors and offsets in the design's order
// (anchors 3i..3i+2, offsets 12+i) from calibrate()'s (per cable: anchor, offset).
DesignInformation design_order(const Eigen::MatrixXd& fit_covariance) {
  std::array<int, kDesignParameters> from{};
  for (int i = 0; i < kCableCount; ++i) {
    for (int a = 0; a < 3; ++a) from[3 * i + a] = 4 * i + a;
    from[3 * kCableCount + i] = 4 * i + 3;
  }
  DesignInformation out;
  for (int r = 0; r < kDesignParameters; ++r) {
    for (int c = 0; c < kDesignParameters; ++c) out(r, c) = fit_covariance(from[r], from[c]);
  }
  return out;
}

// The forecast counts at least this fraction of the predicted progress:
// a run of re-solves that showed none must not forecast for ever.
constexpr double kMinDiscount = 0.1;

// Moves of the estimate, in its own sigmas, that re-plan the candidates.
constexpr double kReplanSignificance = 3.0;

double square(double x) { return x * x; }

// Farthest-point order over every candidate, from the one nearest their centre.
std::vector<int> spread_order(const std::vector<Waypoint>& candidates) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Waypoint& w : candidates) centre += w.rest.world_T_platform.position_world / candidates.size();
  return spread_waypoints(candidates, centre, static_cast<int>(candidates.size()));
}

}  // namespace

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::kNotStopped: return "not stopped";
    case StopReason::kTargetReached: return "target reached";
    case StopReason::kMaxCount: return "max count";
    case StopReason::kNoCandidates: return "no candidates left";
  }
  return "?";
}

SequentialPlanner::SequentialPlanner(const Robot& nominal, std::vector<Waypoint> candidates, const Pose& start,
                                     const SequentialOptions& options, std::optional<CandidateSource> source)
    : nominal_(nominal),
      candidates_(std::move(candidates)),
      options_(options),
      source_(std::move(source)),
      used_(candidates_.size(), false),
      at_(start),
      estimate_(nominal),
      planned_anchors_(nominal_anchors(nominal)) {
  if (source_) estimate_offset_m_ = planned_offset_m_ = source_->payout_offset_m;
  if (candidates_.empty()) {
    status_.stop = StopReason::kNoCandidates;
    return;
  }
  spread_ = spread_order(candidates_);
  const int max_initial = std::max(1, std::min<int>(options_.max_count, spread_.size()));
  std::vector<Pose> poses;
  for (const int k : spread_) {
    if (static_cast<int>(poses.size()) >= max_initial) break;
    if (static_cast<int>(poses.size()) >= options_.min_count && identifiable(nominal_, poses)) break;
    poses.push_back(candidates_[k].rest.world_T_platform);
  }
  const std::vector<int> order = tour_order(nominal_, nominal_anchors(nominal_), start, poses);
  for (const int k : order) initial_.push_back(spread_[k]);
  next_ = initial_.front();
  estimate_initial_left();
}

void SequentialPlanner::estimate_initial_left() {
  Pose from = at_;
  status_.estimated_time_left_s = 0.0;
  for (std::size_t j = initial_done_; j < initial_.size(); ++j) {
    status_.estimated_time_left_s += move_time_s(from, initial_[j]);
    from = candidates_[initial_[j]].rest.world_T_platform;
  }
  status_.estimated_samples_left = static_cast<int>(initial_.size() - initial_done_);
}

double SequentialPlanner::move_time_s(const Pose& from, int index) const {
  const double travel_m =
      winch_travel_m(nominal_, nominal_anchors(estimate_), from, candidates_[index].rest.world_T_platform);
  return travel_m / options_.winch_speed_mps + options_.settle_s;
}

void SequentialPlanner::add_sample(int index, const Sample& sample) {
  modelled_time_s_ += move_time_s(at_, index);
  used_[index] = true;
  visited_.push_back(candidates_[index].rest.world_T_platform.position_world);
  at_ = candidates_[index].rest.world_T_platform;
  samples_.push_back(sample);
  status_.samples = static_cast<int>(samples_.size());
  moved_on();
}

void SequentialPlanner::skip(int index) {
  used_[index] = true;
  visited_.push_back(candidates_[index].rest.world_T_platform.position_world);
  moved_on();
}

void SequentialPlanner::moved_on() {
  status_.fell_back = false;
  while (initial_done_ < initial_.size() && used_[initial_[initial_done_]]) ++initial_done_;
  if (initial_done_ < initial_.size()) {
    next_ = initial_[initial_done_];
    estimate_initial_left();
    return;
  }
  if (resolved_samples_ != samples_.size()) resolve();
  decide();
}

void SequentialPlanner::resolve() {
  resolved_samples_ = samples_.size();
  CalibrationResult fit = options_.resolve ? options_.resolve(estimate_, samples_, options_.solver)
                                           : calibrate(estimate_, samples_, options_.solver);
  status_.solved = fit.ok;
  if (!fit.ok) return;
  fit_ = std::move(fit);
  double anchor_m = 0.0, offset_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) {
    const WinchCalibration& w = fit_.calibration.winches[i];
    estimate_.winches[i].anchor_world = w.anchor_world;
    estimate_offset_m_[i] = w.offset_m;
    anchor_m = std::max(anchor_m, w.anchor_sigma.maxCoeff());
    offset_m = std::max(offset_m, w.offset_sigma_m);
  }
  status_.largest_anchor_sigma_m = anchor_m;
  status_.largest_offset_sigma_m = offset_m;
  status_.largest_sigma_ratio =
      std::max(anchor_m / options_.target_anchor_sigma_m, offset_m / options_.target_offset_sigma_m);
  // The forecast's discount: how much of the progress the information
  // predicted for the last waypoint the re-solve shows.
  const double ratio_sq = status_.largest_sigma_ratio * status_.largest_sigma_ratio;
  if (predicted_ratio_sq_ && ratio_sq_before_ > 0.0 && *predicted_ratio_sq_ > 0.0 && ratio_sq > 0.0) {
    realised_progress_ += std::log(ratio_sq_before_ / ratio_sq);
    predicted_progress_ += std::log(ratio_sq_before_ / *predicted_ratio_sq_);
  }
  predicted_ratio_sq_.reset();
  replan();
}

void SequentialPlanner::replan() {
  if (!source_) return;
  double anchor_moved_m = 0.0, offset_moved_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) {
    anchor_moved_m = std::max(anchor_moved_m, (estimate_.winches[i].anchor_world - planned_anchors_[i]).norm());
    offset_moved_m = std::max(offset_moved_m, std::abs(estimate_offset_m_[i] - planned_offset_m_[i]));
  }
  // Only once the fit says the candidates' anchors or offsets are off: by
  // more than the target, and by more than three of the fit's own sigmas
  // (a fit that knows little, or a failing one, leaves them as they are).
  const bool anchors_off = anchor_moved_m > std::max(options_.target_anchor_sigma_m,
                                                     kReplanSignificance * status_.largest_anchor_sigma_m);
  const bool offsets_off = offset_moved_m > std::max(options_.target_offset_sigma_m,
                                                     kReplanSignificance * status_.largest_offset_sigma_m);
  if (!anchors_off && !offsets_off) return;
  WaypointPlan plan = candidate_waypoints(estimate_, estimate_offset_m_, source_->options);
  if (!plan.ok() || plan.waypoints.empty()) return;
  candidates_ = std::move(plan.waypoints);
  planned_anchors_ = nominal_anchors(estimate_);
  planned_offset_m_ = estimate_offset_m_;
  ++status_.replans;
  // Where a sample was taken or could not be, a new candidate nearer than
  // half the grid's finest step stays out, as a measured or skipped
  // candidate does without a re-plan.
  Eigen::Vector3d low = candidates_.front().rest.world_T_platform.position_world, high = low;
  for (const Waypoint& w : candidates_) {
    low = low.cwiseMin(w.rest.world_T_platform.position_world);
    high = high.cwiseMax(w.rest.world_T_platform.position_world);
  }
  const Eigen::Vector3d extent = high - low;
  const double radius_m = 0.5 * std::min({extent.x() / std::max(source_->options.grid_xy - 1, 1),
                                          extent.y() / std::max(source_->options.grid_xy - 1, 1),
                                          extent.z() / std::max(source_->options.grid_z - 1, 1)});
  used_.assign(candidates_.size(), false);
  for (std::size_t k = 0; k < candidates_.size(); ++k) {
    for (const Eigen::Vector3d& p : visited_) {
      if ((candidates_[k].rest.world_T_platform.position_world - p).norm() < radius_m) used_[k] = true;
    }
  }
  spread_ = spread_order(candidates_);
}

void SequentialPlanner::decide() {
  next_.reset();
  const int n = static_cast<int>(samples_.size());
  const double ratio = status_.largest_sigma_ratio;
  status_.estimated_samples_left = 0;
  status_.estimated_time_left_s = 0.0;
  if (status_.solved && ratio <= 1.0 && n >= options_.min_count) {
    status_.stop = StopReason::kTargetReached;
    return;
  }
  if (n >= options_.max_count) {
    status_.stop = StopReason::kMaxCount;
    return;
  }
  if (!status_.solved) {
    // Without a fit the information has no estimate to be evaluated at.
    for (const int k : spread_) {
      if (used_[k]) continue;
      next_ = k;
      status_.fell_back = true;
      status_.estimated_samples_left = 1;
      status_.estimated_time_left_s = -1.0;
      return;
    }
    status_.stop = StopReason::kNoCandidates;
    return;
  }
  const Robot design = design_robot();
  const DesignInformation prior = prior_information(design);
  const std::optional<Choice> best = choose(design, prior, used_, at_);
  if (!best) {
    status_.stop = StopReason::kNoCandidates;
    return;
  }
  next_ = best->index;
  ratio_sq_before_ = ratio * ratio;
  predicted_ratio_sq_ = ratio_sq(best->after);
  forecast(prior);
}

double SequentialPlanner::ratio_sq(const Vector& variance) const {
  return std::max((variance.head<3 * kCableCount>() / square(options_.target_anchor_sigma_m)).maxCoeff(),
                  (variance.tail<kCableCount>() / square(options_.target_offset_sigma_m)).maxCoeff());
}

void SequentialPlanner::forecast(const DesignInformation& prior) {
  const double ratio_sq_now = square(status_.largest_sigma_ratio);
  const double needed = std::log(ratio_sq_now);  // progress to a ratio of 1
  // The progress predicted, as predicted, until the re-solves have shown otherwise.
  const double discount = predicted_progress_ > 0.0
                              ? std::clamp(realised_progress_ / predicted_progress_, kMinDiscount, 1.0)
                              : 1.0;
  const Robot design = design_robot();
  const double predicted_now = ratio_sq(prior.ldlt().solve(DesignInformation::Identity()).diagonal());
  std::vector<bool> taken = used_;
  DesignInformation information = prior;
  Pose from = at_;
  const int room = options_.max_count - static_cast<int>(samples_.size());
  int steps = 0;
  double time_s = 0.0;
  while (steps < room) {
    const std::optional<Choice> c = choose(design, information, taken, from);
    if (!c) break;
    ++steps;
    time_s += move_time_s(from, c->index);
    from = candidates_[c->index].rest.world_T_platform;
    taken[c->index] = true;
    information = c->posterior;
    if (discount * std::log(predicted_now / ratio_sq(c->after)) >= needed) break;
  }
  status_.estimated_samples_left = steps;
  status_.estimated_time_left_s = time_s;
}

Robot SequentialPlanner::design_robot() const {
  // The information is weighed with the rows' own noise (the mean of their
  // sigmas), as the fit weighs them.
  Robot design = estimate_;
  if (samples_.empty()) return design;
  double encoder_m = 0.0, position_m = 0.0, orientation_rad = 0.0;
  for (const Sample& s : samples_) {
    const SampleSigmas sigma = reading_sigmas(nominal_, s);
    for (const double e : sigma.encoder_m) encoder_m += e / (kCableCount * samples_.size());
    position_m += sigma.position_m / samples_.size();
    orientation_rad += sigma.orientation_rad / samples_.size();
  }
  design.noise.encoder_m = encoder_m;
  design.noise.position_m = position_m;
  design.noise.orientation_rad = orientation_rad;
  return design;
}

DesignInformation SequentialPlanner::prior_information(const Robot& design) const {
  if (status_.solved) return design_order(fit_.global_covariance).ldlt().solve(DesignInformation::Identity());
  std::vector<Pose> measured;
  for (const Sample& s : samples_) measured.push_back(Pose{s.position_world, s.world_R_platform});
  return design_information(design, measured);
}

std::optional<SequentialPlanner::Choice> SequentialPlanner::choose(const Robot& design,
                                                                   const DesignInformation& prior,
                                                                   const std::vector<bool>& taken,
                                                                   const Pose& from) const {
  const Vector before = prior.ldlt().solve(DesignInformation::Identity()).diagonal();
  Vector target_sq;
  target_sq.head<3 * kCableCount>().setConstant(square(options_.target_anchor_sigma_m));
  target_sq.tail<kCableCount>().setConstant(square(options_.target_offset_sigma_m));

  // Gain above the targets first; when no candidate lowers a variance that
  // is still above its target (min_count not reached yet), the plain trace.
  for (const Vector& targets : {target_sq, Vector::Zero().eval()}) {
    Choice best;
    double best_score = 0.0;
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (taken[k]) continue;
      const DesignInformation posterior = prior + pose_information(design, candidates_[k].rest.world_T_platform);
      const Vector after = posterior.ldlt().solve(DesignInformation::Identity()).diagonal();
      const double score =
          gain(before, after, targets) / (move_time_s(from, static_cast<int>(k)) + options_.score_horizon_s);
      if (score > best_score) {
        best = Choice{static_cast<int>(k), posterior, after};
        best_score = score;
      }
    }
    if (best.index >= 0) return best;
  }
  return std::nullopt;
}

}  // namespace cdpr::calibration
