#include "src/calibration/waypoint_sequence.h"

#include <algorithm>

#include "src/calibration/waypoint_tour.h"

namespace cdpr::calibration {

const char* to_string(WaypointStrategy strategy) {
  switch (strategy) {
    case WaypointStrategy::kSpread: return "spread";
    case WaypointStrategy::kInformative: return "informative";
    case WaypointStrategy::kSequential: return "sequential";
  }
  return "?";
}

std::string WaypointSequence::start(const Robot& robot, const std::array<double, kCableCount>& offset_m,
                                    const Eigen::Vector3d& start_world, const PlannerOptions& planner,
                                    WaypointStrategy strategy, const SequentialOptions& sequential,
                                    hal::TimeUs now_us) {
  *this = WaypointSequence{};
  strategy_ = strategy;
  robot_ = robot;
  sequential_options_ = sequential;
  start_pose_ = at_ = Pose{start_world, Eigen::Quaterniond::Identity()};
  started_us_ = estimated_at_us_ = now_us;
  PlannerOptions options = planner;
  options.selection =
      strategy == WaypointStrategy::kInformative ? WaypointSelection::kInformative : WaypointSelection::kSpread;
  if (strategy != WaypointStrategy::kSequential) {
    plan_ = plan_waypoints(robot, offset_m, start_world, options);
    if (!plan_.ok()) return plan_.problem;
    time_left_s_ = modelled_left_s();
    return "";
  }
  plan_ = candidate_waypoints(robot, offset_m, options);
  if (!plan_.ok()) return plan_.problem;
  if (plan_.waypoints.empty()) return "no feasible waypoint among the candidates";
  sequential_.emplace(robot, plan_.waypoints, start_pose_, sequential, CandidateSource{options, offset_m});
  time_left_s_ = modelled_left_s();
  return "";
}

std::string WaypointSequence::start_given(const Robot& robot, const std::array<double, kCableCount>& offset_m,
                                          const Eigen::Vector3d& start_world, const PlannerOptions& planner,
                                          const std::vector<Eigen::Vector3d>& positions_world,
                                          const SequentialOptions& sequential, hal::TimeUs now_us) {
  *this = WaypointSequence{};
  given_ = true;
  robot_ = robot;
  sequential_options_ = sequential;
  start_pose_ = at_ = Pose{start_world, Eigen::Quaterniond::Identity()};
  started_us_ = estimated_at_us_ = now_us;
  plan_ = given_waypoints(robot, offset_m, positions_world, planner);
  if (!plan_.ok()) return plan_.problem;
  time_left_s_ = modelled_left_s();
  return "";
}

int WaypointSequence::planned() const {
  return sequential_ ? sequential_options_.max_count : static_cast<int>(plan_.waypoints.size());
}

const Waypoint* WaypointSequence::current() const {
  if (!sequential_) {
    return visited_ < static_cast<int>(plan_.waypoints.size()) ? &plan_.waypoints[visited_] : nullptr;
  }
  const std::optional<int> index = sequential_->next();
  return index ? &sequential_->candidates()[*index] : nullptr;
}

void WaypointSequence::sampled(const Sample& sample, hal::TimeUs now_us) {
  const Pose reached = current()->rest.world_T_platform;
  if (sequential_) sequential_->add_sample(*sequential_->next(), sample);
  visited(reached, now_us);
}

void WaypointSequence::skipped(hal::TimeUs now_us) {
  const Pose reached = current()->rest.world_T_platform;
  if (sequential_) sequential_->skip(*sequential_->next());
  visited(reached, now_us);
}

void WaypointSequence::visited(const Pose& reached, hal::TimeUs now_us) {
  remark_.clear();
  if (sequential_ && sequential_->status().fell_back) {
    remark_ = "re-solve with " + std::to_string(sequential_->samples().size()) +
              " samples failed: next waypoint in spread order";
  }
  modelled_spent_s_ += modelled_s(at_, reached);
  at_ = reached;
  ++visited_;
  estimated_at_us_ = now_us;
  const double modelled_left_s = this->modelled_left_s();
  const double spent_s = 1e-6 * static_cast<double>(now_us - started_us_);
  const double scale = modelled_spent_s_ > 0.0 ? spent_s / modelled_spent_s_ : 1.0;
  time_left_s_ = modelled_left_s < 0.0 ? -1.0 : modelled_left_s * scale;
}

double WaypointSequence::modelled_s(const Pose& from, const Pose& to) const {
  return winch_travel_m(robot_, nominal_anchors(robot_), from, to) / sequential_options_.winch_speed_mps +
         sequential_options_.settle_s;
}

double WaypointSequence::modelled_left_s() const {
  if (sequential_) return sequential_->status().estimated_time_left_s;
  double left_s = 0.0;
  Pose from = at_;
  for (std::size_t k = static_cast<std::size_t>(visited_); k < plan_.waypoints.size(); ++k) {
    left_s += modelled_s(from, plan_.waypoints[k].rest.world_T_platform);
    from = plan_.waypoints[k].rest.world_T_platform;
  }
  return left_s;
}

int WaypointSequence::expected_count() const {
  if (!sequential_) return planned();
  const SequentialStatus s = sequential_->status();
  return s.stop != StopReason::kNotStopped ? visited_ : visited_ + std::max(s.estimated_samples_left, 1);
}

std::optional<double> WaypointSequence::largest_anchor_sigma_m() const {
  if (!sequential_ || !sequential_->last_fit().ok) return std::nullopt;
  return sequential_->status().largest_anchor_sigma_m;
}

std::optional<double> WaypointSequence::largest_offset_sigma_m() const {
  if (!sequential_ || !sequential_->last_fit().ok) return std::nullopt;
  return sequential_->status().largest_offset_sigma_m;
}

std::string WaypointSequence::stop_reason() const {
  if (!sequential_) return current() ? "" : "plan done";
  return sequential_->status().stop == StopReason::kNotStopped ? "" : to_string(sequential_->status().stop);
}

}  // namespace cdpr::calibration
