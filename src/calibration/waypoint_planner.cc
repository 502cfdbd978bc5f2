#include "src/calibration/waypoint_planner.h"

#include <algorithm>
#include <limits>
#include <random>

#include "solver/calibration/pose_design.h"
#include "src/calibration/message_text.h"
#include "src/calibration/waypoint_tour.h"

namespace cdpr::calibration {
namespace {

// Why a solved rest pose violates a limit; empty when within all limits.
std::string limit_violation(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                            const StaticPose& rest, const std::array<double, kCableCount>& payout_m,
                            const PlannerOptions& options) {
  for (int i = 0; i < kCableCount; ++i) {
    const std::string cable = "cable " + std::to_string(i);
    const double chord_m =
        (rest.world_T_platform.transform(robot.winches[i].attachment_platform) - anchors[i]).norm();
    const double sag_excess = rest.arc_length_m[i] / chord_m - 1.0;
    if (!(sag_excess <= options.max_sag_excess)) {
      return cable + " sag excess " + significant(100.0 * sag_excess) + " % above " +
             significant(100.0 * options.max_sag_excess) + " % (arc " + significant(rest.arc_length_m[i]) +
             " m over chord " + significant(chord_m) + " m)";
    }
    if (rest.tension_n[i] < options.min_tension_n) {
      return cable + " tension " + significant(rest.tension_n[i]) + " N below " +
             significant(options.min_tension_n) + " N";
    }
    if (rest.tension_n[i] > options.max_tension_n) {
      return cable + " tension " + significant(rest.tension_n[i]) + " N above " +
             significant(options.max_tension_n) + " N";
    }
    if (payout_m[i] < options.min_payout_m || payout_m[i] > options.max_payout_m) {
      return cable + " payout " + significant(payout_m[i]) + " m outside [" + significant(options.min_payout_m) +
             ", " + significant(options.max_payout_m) + "] m";
    }
  }
  return {};
}

struct Box {
  Eigen::Vector3d low, high;
};

Box workspace_box(const Robot& robot, const PlannerOptions& options) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Winch& winch : robot.winches) {
    low = low.cwiseMin(winch.anchor_world);
    high = high.cwiseMax(winch.anchor_world);
  }
  low.head<2>().array() += options.margin_m;
  high.head<2>().array() -= options.margin_m;
  low.z() = options.z_min_m;
  high.z() = options.z_max_m;
  return {low, high};
}

std::vector<Eigen::Vector3d> jittered_grid(const Box& box, const PlannerOptions& options) {
  std::mt19937 random(options.seed);
  std::uniform_real_distribution<double> jitter(-options.jitter_fraction, options.jitter_fraction);
  const Eigen::Vector3i counts(options.grid_xy, options.grid_xy, options.grid_z);
  std::vector<Eigen::Vector3d> points;
  for (int ix = 0; ix < counts.x(); ++ix) {
    for (int iy = 0; iy < counts.y(); ++iy) {
      for (int iz = 0; iz < counts.z(); ++iz) {
        const Eigen::Vector3i index(ix, iy, iz);
        Eigen::Vector3d point;
        for (int axis = 0; axis < 3; ++axis) {
          // Cell centres, so the jitter never leaves the box.
          const double step = (box.high(axis) - box.low(axis)) / counts(axis);
          point(axis) = box.low(axis) + step * (index(axis) + 0.5 + jitter(random));
        }
        points.push_back(point);
      }
    }
  }
  return points;
}

}  // namespace

std::vector<int> spread_waypoints(const std::vector<Waypoint>& candidates, const Eigen::Vector3d& centre, int count) {
  std::vector<int> chosen;
  std::vector<double> distance(candidates.size(), std::numeric_limits<double>::infinity());
  int next = 0;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if ((candidates[k].rest.world_T_platform.position_world - centre).norm() <
        (candidates[next].rest.world_T_platform.position_world - centre).norm()) {
      next = static_cast<int>(k);
    }
  }
  while (static_cast<int>(chosen.size()) < count) {
    chosen.push_back(next);
    const Eigen::Vector3d& p = candidates[next].rest.world_T_platform.position_world;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      distance[k] = std::min(distance[k], (candidates[k].rest.world_T_platform.position_world - p).norm());
    }
    next = static_cast<int>(std::max_element(distance.begin(), distance.end()) - distance.begin());
  }
  return chosen;
}

namespace {

// A-optimal selection on the robot's nominal geometry.
std::vector<int> informative_points(const Robot& robot, const std::vector<Waypoint>& candidates, int count) {
  std::vector<Pose> poses;
  poses.reserve(candidates.size());
  for (const Waypoint& w : candidates) poses.push_back(w.rest.world_T_platform);
  return choose_informative_poses(robot, poses, count);
}

// A short tour from `start` (waypoint_tour.h) on the nominal anchors.
std::vector<Waypoint> travel_order(const Robot& robot, std::vector<Waypoint> waypoints, const Eigen::Vector3d& start) {
  std::vector<Pose> stops;
  stops.reserve(waypoints.size());
  for (const Waypoint& w : waypoints) stops.push_back(w.rest.world_T_platform);
  std::vector<Waypoint> ordered;
  ordered.reserve(waypoints.size());
  for (const int k : tour_order(robot, nominal_anchors(robot), Pose{start, Eigen::Quaterniond::Identity()}, stops)) {
    ordered.push_back(std::move(waypoints[k]));
  }
  return ordered;
}

}  // namespace

std::string check_planner_options(const Robot& robot, const PlannerOptions& options) {
  if (robot.cable_count() != kCableCount) return "the planner needs exactly 4 cables";
  if (options.waypoint_count < 1) return "waypoint count must be at least 1";
  if (options.grid_xy < 1 || options.grid_z < 1) return "grid counts must be at least 1";
  if (!(options.jitter_fraction >= 0.0 && options.jitter_fraction < 0.5)) return "jitter fraction must be in [0, 0.5)";
  if (!(options.z_min_m <= options.z_max_m)) return "z band is empty (z_min > z_max)";
  if (!(options.min_tension_n < options.max_tension_n)) return "tension limits are empty (min >= max)";
  if (!(options.max_sag_excess > 0.0)) return "max sag excess must be > 0";
  const Box box = workspace_box(robot, options);
  if (!(box.low.x() < box.high.x() && box.low.y() < box.high.y())) {
    return "margin " + significant(options.margin_m) + " m leaves no workspace inside the anchors";
  }
  return {};
}

WaypointPlan candidate_waypoints(const Robot& robot, const std::array<double, kCableCount>& payout_offset_m,
                                 const PlannerOptions& options) {
  WaypointPlan plan;
  plan.problem = check_planner_options(robot, options);
  if (!plan.ok()) return plan;
  const auto anchors = nominal_anchors(robot);
  for (const Eigen::Vector3d& position : jittered_grid(workspace_box(robot, options), options)) {
    std::string no_rest;
    auto rest = solve_static_pose(robot, anchors, position, &no_rest);
    if (!rest) {
      plan.rejected.push_back({position, std::move(no_rest)});
      continue;
    }
    Waypoint waypoint{std::move(*rest), {}};
    for (int i = 0; i < kCableCount; ++i) waypoint.payout_m[i] = waypoint.rest.arc_length_m[i] + payout_offset_m[i];
    if (std::string why = limit_violation(robot, anchors, waypoint.rest, waypoint.payout_m, options); !why.empty()) {
      plan.rejected.push_back({position, std::move(why)});
      continue;
    }
    plan.waypoints.push_back(std::move(waypoint));
  }
  return plan;
}

WaypointPlan plan_waypoints(const Robot& robot, const std::array<double, kCableCount>& payout_offset_m,
                            const Eigen::Vector3d& start_world, const PlannerOptions& options) {
  WaypointPlan plan = candidate_waypoints(robot, payout_offset_m, options);
  if (!plan.ok()) return plan;
  std::vector<Waypoint> feasible = std::move(plan.waypoints);
  plan.waypoints.clear();
  if (static_cast<int>(feasible.size()) < options.waypoint_count) {
    plan.problem = "only " + std::to_string(feasible.size()) + " of " + std::to_string(options.waypoint_count) +
                   " waypoints feasible within the limits (" + std::to_string(plan.rejected.size()) + " rejected)";
    return plan;
  }
  const Box box = workspace_box(robot, options);
  std::vector<Waypoint> chosen;
  for (const int k : options.selection == WaypointSelection::kInformative
                         ? informative_points(robot, feasible, options.waypoint_count)
                         : spread_waypoints(feasible, 0.5 * (box.low + box.high), options.waypoint_count)) {
    chosen.push_back(feasible[k]);
  }
  plan.waypoints =
      options.order == WaypointOrder::kTour ? travel_order(robot, std::move(chosen), start_world) : std::move(chosen);
  return plan;
}

std::string outside_workspace(const Robot& robot, const Eigen::Vector3d& position_world,
                              const PlannerOptions& options) {
  const Box box = workspace_box(robot, options);
  static constexpr const char* kAxis[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    if (!(position_world(axis) >= box.low(axis) && position_world(axis) <= box.high(axis))) {
      return std::string(kAxis[axis]) + " " + significant(position_world(axis)) + " m outside the workspace [" +
             significant(box.low(axis)) + ", " + significant(box.high(axis)) + "] m";
    }
  }
  return {};
}

WaypointPlan given_waypoints(const Robot& robot, const std::array<double, kCableCount>& payout_offset_m,
                             const std::vector<Eigen::Vector3d>& positions_world, const PlannerOptions& options) {
  WaypointPlan plan;
  plan.problem = check_planner_options(robot, options);
  if (!plan.ok()) return plan;
  if (positions_world.empty()) {
    plan.problem = "no waypoints given";
    return plan;
  }
  const auto anchors = nominal_anchors(robot);
  for (std::size_t k = 0; k < positions_world.size(); ++k) {
    const Eigen::Vector3d& position = positions_world[k];
    const std::string which = "waypoint " + std::to_string(k + 1) + " of " + std::to_string(positions_world.size()) +
                              " (x " + significant(position.x()) + ", y " + significant(position.y()) + ", z " +
                              significant(position.z()) + "): ";
    std::string why = outside_workspace(robot, position, options);
    std::optional<StaticPose> rest;
    if (why.empty()) rest = solve_static_pose(robot, anchors, position, &why);
    Waypoint waypoint;
    if (rest) {
      waypoint.rest = std::move(*rest);
      for (int i = 0; i < kCableCount; ++i) waypoint.payout_m[i] = waypoint.rest.arc_length_m[i] + payout_offset_m[i];
      why = limit_violation(robot, anchors, waypoint.rest, waypoint.payout_m, options);
    } else if (why.empty()) {
      why = "no rest pose";
    }
    if (!why.empty()) {
      plan.rejected.push_back({position, why});
      plan.waypoints.clear();
      plan.problem = which + why;
      return plan;
    }
    plan.waypoints.push_back(std::move(waypoint));
  }
  return plan;
}

Expected<std::array<double, kCableCount>, std::string> estimate_payout_offsets(
    const Robot& robot, const Eigen::Vector3d& position_world, const std::array<double, kCableCount>& encoder_m) {
  std::string no_rest;
  const auto rest = solve_static_pose(robot, nominal_anchors(robot), position_world, &no_rest);
  if (!rest) return Unexpected{"cannot model the start pose: " + no_rest};
  std::array<double, kCableCount> offsets{};
  for (int i = 0; i < kCableCount; ++i) offsets[i] = encoder_m[i] - rest->arc_length_m[i];
  return offsets;
}

}  // namespace cdpr::calibration
