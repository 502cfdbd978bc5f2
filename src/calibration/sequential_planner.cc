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
                                     const SequentialOptions& options)
    : nominal_(nominal),
      candidates_(std::move(candidates)),
      options_(options),
      used_(candidates_.size(), false),
      at_(start),
      estimate_(nominal) {
  if (candidates_.empty()) {
    status_.stop = StopReason::kNoCandidates;
    return;
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Waypoint& w : candidates_) centre += w.rest.world_T_platform.position_world / candidates_.size();
  const std::vector<int> spread = spread_waypoints(candidates_, centre, static_cast<int>(candidates_.size()));
  const int max_initial = std::max(1, std::min<int>(options_.max_count, spread.size()));
  std::vector<Pose> poses;
  for (const int k : spread) {
    if (static_cast<int>(poses.size()) >= max_initial) break;
    if (static_cast<int>(poses.size()) >= options_.min_count && identifiable(nominal_, poses)) break;
    poses.push_back(candidates_[k].rest.world_T_platform);
  }
  const std::vector<int> order = tour_order(nominal_, nominal_anchors(nominal_), start, poses);
  for (const int k : order) initial_.push_back(spread[k]);
  next_ = initial_.front();
}

std::optional<int> SequentialPlanner::next() { return next_; }

double SequentialPlanner::move_time_s(int index) const {
  const double travel_m =
      winch_travel_m(nominal_, nominal_anchors(estimate_), at_, candidates_[index].rest.world_T_platform);
  return travel_m / options_.winch_speed_mps + options_.settle_s;
}

void SequentialPlanner::add_sample(int index, const Sample& sample) {
  modelled_time_s_ += move_time_s(index);
  used_[index] = true;
  at_ = candidates_[index].rest.world_T_platform;
  samples_.push_back(sample);
  status_.samples = static_cast<int>(samples_.size());
  while (initial_done_ < initial_.size() && used_[initial_[initial_done_]]) ++initial_done_;
  if (initial_done_ < initial_.size()) {
    next_ = initial_[initial_done_];
    return;
  }
  resolve();
  decide();
}

void SequentialPlanner::skip(int index) {
  used_[index] = true;
  while (initial_done_ < initial_.size() && used_[initial_[initial_done_]]) ++initial_done_;
  if (initial_done_ < initial_.size()) {
    next_ = initial_[initial_done_];
    return;
  }
  decide();
}

void SequentialPlanner::resolve() {
  CalibrationResult fit = calibrate(estimate_, samples_, options_.solver);
  status_.solved = fit.ok;
  if (!fit.ok) return;
  fit_ = std::move(fit);
  double anchor_m = 0.0, offset_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) {
    const WinchCalibration& w = fit_.calibration.winches[i];
    estimate_.winches[i].anchor_world = w.anchor_world;
    anchor_m = std::max(anchor_m, w.anchor_sigma.maxCoeff());
    offset_m = std::max(offset_m, w.offset_sigma_m);
  }
  status_.largest_anchor_sigma_m = anchor_m;
  status_.largest_offset_sigma_m = offset_m;
  status_.largest_sigma_ratio =
      std::max(anchor_m / options_.target_anchor_sigma_m, offset_m / options_.target_offset_sigma_m);
}

void SequentialPlanner::decide() {
  next_.reset();
  const int n = static_cast<int>(samples_.size());
  const double ratio = status_.largest_sigma_ratio;
  const int room = std::max(options_.max_count - n, 0);
  status_.estimated_samples_left =
      ratio > 1.0 ? std::min(room, static_cast<int>(std::ceil(n * (ratio * ratio - 1.0)))) : 0;
  status_.estimated_time_left_s = n > 0 ? status_.estimated_samples_left * modelled_time_s_ / n : 0.0;
  if (status_.solved && ratio <= 1.0 && n >= options_.min_count) {
    status_.stop = StopReason::kTargetReached;
  } else if (n >= options_.max_count) {
    status_.stop = StopReason::kMaxCount;
  } else if (const std::optional<int> best = best_candidate()) {
    next_ = best;
  } else {
    status_.stop = StopReason::kNoCandidates;
  }
}

std::optional<int> SequentialPlanner::best_candidate() const {
  // The information is weighed with the rows' own noise (the mean of their
  // sigmas), as the fit weighs them.
  Robot design = estimate_;
  if (!samples_.empty()) {
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
  }
  DesignInformation prior;
  if (status_.solved) {
    prior = design_order(fit_.global_covariance).ldlt().solve(DesignInformation::Identity());
  } else {
    std::vector<Pose> measured;
    for (const Sample& s : samples_) measured.push_back(Pose{s.position_world, s.world_R_platform});
    prior = design_information(design, measured);
  }
  const DesignVector before = prior.ldlt().solve(DesignInformation::Identity()).diagonal();
  DesignVector target_sq;
  target_sq.head<3 * kCableCount>().setConstant(options_.target_anchor_sigma_m * options_.target_anchor_sigma_m);
  target_sq.tail<kCableCount>().setConstant(options_.target_offset_sigma_m * options_.target_offset_sigma_m);

  // Gain above the targets first; when no candidate lowers a variance that
  // is still above its target (min_count not reached yet), the plain trace.
  for (const DesignVector& targets : {target_sq, DesignVector::Zero().eval()}) {
    int best = -1;
    double best_score = 0.0;
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (used_[k]) continue;
      const DesignInformation posterior = prior + pose_information(design, candidates_[k].rest.world_T_platform);
      const DesignVector after = posterior.ldlt().solve(DesignInformation::Identity()).diagonal();
      const double score =
          gain(before, after, targets) / (move_time_s(static_cast<int>(k)) + options_.score_horizon_s);
      if (score > best_score) {
        best = static_cast<int>(k);
        best_score = score;
      }
    }
    if (best >= 0) return best;
  }
  return std::nullopt;
}

}  // namespace cdpr::calibration
