#pragma once
// Plans the static poses of one field calibration from the nominal geometry
// (docs/DESIGN.md step 3): well spread over the workspace so that anchors and
// offsets are observable, each converted to winch payout targets with the
// sagging-cable model (solver/model/static_pose.h) and checked against the limits.
//
// Workspace: the anchors' horizontal bounding box inset by `margin_m` on each
// side, times the world-z band [z_min_m, z_max_m]. Candidates: a jittered grid
// (grid_xy x grid_xy x grid_z, jitter a fraction of the step, seeded so a plan
// is reproducible). Every candidate is solved for its rest pose and checked:
// each cable's tension within [min_tension_n, max_tension_n], each payout
// target within [min_payout_m, max_payout_m], and each cable's sag excess
// (arc length over chord, minus one) at most max_sag_excess. The statics at
// a given position can also be met by a cable hanging in a deep loop at low
// tension (tens of metres of extra cable on the large robot): such a pose is
// not where a controller would put the robot, the true robot cannot be led
// there by paying out, and a small anchor error moves it far. From the
// feasible ones, `waypoint_count` are picked (WaypointSelection), then
// ordered as a short tour from the start position (waypoint_tour.h).
// Rejected candidates are returned with the reason.
//
// Payout target of cable i = arc length (Eq. 4) + payout_offset_m[i], the
// encoder offset: from the previous calibration, or estimated at the start
// pose with estimate_payout_offsets().
// Pure logic: no I/O, no clock.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/model/robot.h"
#include "solver/model/static_pose.h"
#include "src/formats/expected.h"

namespace cdpr::calibration {

// How the waypoints are picked from the feasible candidates.
enum class WaypointSelection {
  // Farthest-point: the first nearest the box centre, then each the farthest
  // from those chosen. Spread evenly, whatever the geometry.
  kSpread,
  // A-optimal (solver/calibration/pose_design.h): each the one that lowers the summed
  // Cramer-Rao variance of anchors and offsets most, on the nominal anchors.
  // Smaller anchor and offset sigmas than kSpread for the same count
  // (docs/calibration.md); poses crowd towards the workspace's edges.
  kInformative,
};

// The order in which a fixed plan is driven.
enum class WaypointOrder {
  // A short tour from where the platform starts (waypoint_tour.h): the
  // robot's time goes to sampling, not to travel.
  kTour,
  // As selected (spread: centre first, then outwards by farthest point).
  // Kept to compare robot times and to repeat a run made in that order.
  kSelection,
};

// The defaults are the daemon's [waypoints] defaults (a test in
// tests/src/daemon holds the two to each other): the large robot's band.
struct PlannerOptions {
  int waypoint_count = 35;
  double margin_m = 20.0;  // inset from the anchors' xy footprint [m]
  double z_min_m = 5.0;    // world z band of the platform origin [m]
  double z_max_m = 35.0;
  int grid_xy = 8;        // candidates per horizontal axis
  int grid_z = 4;         // candidates along z
  double jitter_fraction = 0.3;  // of the grid step, in [0, 0.5)
  std::uint32_t seed = 1;
  double min_tension_n = 20.0;   // every cable [N]
  double max_tension_n = 3000.0;
  double min_payout_m = -1e9;    // winch travel limits in encoder units [m]
  double max_payout_m = 1e9;
  double max_sag_excess = 0.02;  // (arc length - chord) / chord, every cable
  WaypointSelection selection = WaypointSelection::kSpread;
  WaypointOrder order = WaypointOrder::kTour;
};

struct Waypoint {
  StaticPose rest;                                // predicted rest pose, lengths, tensions
  std::array<double, kCableCount> payout_m{};     // winch targets [m]
};

struct RejectedWaypoint {
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  std::string reason;  // e.g. "cable 2 tension 4.1 N below 20 N"
};

struct WaypointPlan {
  std::vector<Waypoint> waypoints;         // in travel order
  std::vector<RejectedWaypoint> rejected;  // candidates refused, with reasons
  std::string problem;                     // non-empty when no usable plan (options, too few feasible)
  bool ok() const { return problem.empty(); }
};

// Checks the options (counts, band, margin leaving a box); empty when fine.
std::string check_planner_options(const Robot& robot, const PlannerOptions& options);

// Every feasible candidate (in `waypoints`, grid order) and every rejected
// one with its reason; `problem` only for bad options. For strategies that
// pick among the candidates as they go (sequential_planner.h).
WaypointPlan candidate_waypoints(const Robot& robot, const std::array<double, kCableCount>& payout_offset_m,
                                 const PlannerOptions& options);

// Farthest-point order over `candidates` (WaypointSelection::kSpread): the
// one nearest `centre` first. count <= candidates.size().
std::vector<int> spread_waypoints(const std::vector<Waypoint>& candidates, const Eigen::Vector3d& centre, int count);

WaypointPlan plan_waypoints(const Robot& robot, const std::array<double, kCableCount>& payout_offset_m,
                            const Eigen::Vector3d& start_world, const PlannerOptions& options);

// Why `position_world` lies outside the planner's workspace box (the
// anchors' footprint inset by margin_m, the z band); empty when inside.
std::string outside_workspace(const Robot& robot, const Eigen::Vector3d& position_world,
                              const PlannerOptions& options);

// The given positions as waypoints, in the order given: each must lie in the
// workspace box and pass the checks of a planned candidate (a rest, the
// tension band, the sag, the travel limits). The first that does not makes
// the plan's `problem` ("waypoint 3 of 8 (x 120, y 20, z 35): cable 2
// tension 4.1 N below 20 N") and leaves `waypoints` empty: a run drives all
// of them or none. waypoint_count, grid and selection are not used.
WaypointPlan given_waypoints(const Robot& robot, const std::array<double, kCableCount>& payout_offset_m,
                             const std::vector<Eigen::Vector3d>& positions_world, const PlannerOptions& options);

// Encoder offsets from one measured rest pose: reading - modelled arc length
// at that position (its rest orientation, nominal anchors).
Expected<std::array<double, kCableCount>, std::string> estimate_payout_offsets(
    const Robot& robot, const Eigen::Vector3d& position_world, const std::array<double, kCableCount>& encoder_m);

}  // namespace cdpr::calibration
