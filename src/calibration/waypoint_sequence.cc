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
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Waypoint& w : plan_.waypoints) centre += w.rest.world_T_platform.position_world / plan_.waypoints.size();
  spread_order_ = spread_waypoints(plan_.waypoints, centre, static_cast<int>(plan_.waypoints.size()));
  used_.assign(plan_.waypoints.size(), false);
  sequential_.emplace(robot, plan_.waypoints, start_pose_, sequential);
  index_ = sequential_->next();
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
  return index_ ? &plan_.waypoints[*index_] : nullptr;
}

void WaypointSequence::sampled(const Sample& sample, hal::TimeUs now_us) {
  const Pose reached = current()->rest.world_T_platform;
  if (sequential_) {
    used_[*index_] = true;
    sequential_->add_sample(*index_, sample);
  }
  visited(reached, now_us);
}

void WaypointSequence::skipped(hal::TimeUs now_us) {
  const Pose reached = current()->rest.world_T_platform;
  if (sequential_) {
    used_[*index_] = true;
    sequential_->skip(*index_);
  }
  visited(reached, now_us);
}

void WaypointSequence::visited(const Pose& reached, hal::TimeUs now_us) {
  remark_.clear();
  if (sequential_) choose_next();
  modelled_spent_s_ += modelled_s(at_, reached);
  at_ = reached;
  ++visited_;
  estimated_at_us_ = now_us;
  const double modelled_left_s = this->modelled_left_s();
  const double spent_s = 1e-6 * static_cast<double>(now_us - started_us_);
  const double scale = modelled_spent_s_ > 0.0 ? spent_s / modelled_spent_s_ : 1.0;
  time_left_s_ = modelled_left_s < 0.0 ? -1.0 : modelled_left_s * scale;
}

void WaypointSequence::choose_next() {
  index_ = sequential_->next();
  // The planner re-solves once every waypoint of its initial set is done;
  // while that fails, its choice rests on the nominal design alone, so the
  // next waypoint is the next one of the spread order instead.
  const bool initial_done =
      std::all_of(sequential_->initial().begin(), sequential_->initial().end(), [&](int k) { return used_[k]; });
  if (!index_ || !initial_done || sequential_->status().solved) return;
  for (const int k : spread_order_) {
    if (used_[k]) continue;
    index_ = k;
    remark_ = "re-solve with " + std::to_string(sequential_->samples().size()) +
              " samples failed: next waypoint in spread order";
    return;
  }
}

double WaypointSequence::modelled_s(const Pose& from, const Pose& to) const {
  return winch_travel_m(robot_, nominal_anchors(robot_), from, to) / sequential_options_.winch_speed_mps +
         sequential_options_.settle_s;
}

double WaypointSequence::modelled_left_s() const {
  if (sequential_) {
    const SequentialStatus s = sequential_->status();
    const double per_waypoint_s = visited_ > 0 ? modelled_spent_s_ / visited_ : sequential_options_.settle_s;
    if (s.solved) return s.estimated_samples_left * per_waypoint_s;
    // Before the first re-solve: at least the rest of the initial set.
    const auto initial_left = std::count_if(sequential_->initial().begin(), sequential_->initial().end(),
                                            [&](int k) { return !used_[k]; });
    return initial_left > 0 ? static_cast<double>(initial_left) * per_waypoint_s : -1.0;
  }
  double left_s = 0.0;
  Pose from = at_;
  for (std::size_t k = static_cast<std::size_t>(visited_); k < plan_.waypoints.size(); ++k) {
    left_s += modelled_s(from, plan_.waypoints[k].rest.world_T_platform);
    from = plan_.waypoints[k].rest.world_T_platform;
  }
  return left_s;
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
