#include "src/calibration/waypoint_planner.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "../../solver/model/test_robots.h"
#include "large_robot_planner_options.h"
#include "solver/calibration/pose_design.h"
#include "src/calibration/waypoint_tour.h"

namespace cdpr::calibration {
namespace {

const std::array<double, kCableCount> kOffsets{1.5, -2.0, 0.25, 3.0};

TEST(WaypointPlanner, InformativeSelectionDeterminesAnchorsAndOffsetsBetterThanSpread) {
  // GIVEN the large robot, its workspace and limits
  const Robot robot = cdpr::test::large_robot();
  PlannerOptions spread = large_robot_planner_options(), informative = large_robot_planner_options();
  informative.selection = WaypointSelection::kInformative;
  // WHEN 35 waypoints are picked from the same candidates both ways
  const WaypointPlan a = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), spread);
  const WaypointPlan b = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), informative);
  ASSERT_TRUE(a.ok()) << a.problem;
  ASSERT_TRUE(b.ok()) << b.problem;
  ASSERT_EQ(b.waypoints.size(), 35u);
  // THEN the informative ones bound the summed variance of anchors and
  // offsets lower, all distinct
  const auto poses = [](const WaypointPlan& plan) {
    std::vector<Pose> out;
    for (const Waypoint& w : plan.waypoints) out.push_back(w.rest.world_T_platform);
    return out;
  };
  EXPECT_LT(design_variance_sum(robot, poses(b)), 0.8 * design_variance_sum(robot, poses(a)));
  for (std::size_t j = 0; j < b.waypoints.size(); ++j) {
    for (std::size_t k = j + 1; k < b.waypoints.size(); ++k) {
      EXPECT_NE(b.waypoints[j].rest.world_T_platform.position_world, b.waypoints[k].rest.world_T_platform.position_world);
    }
  }
}

TEST(WaypointPlanner, PlansWellSpreadWaypointsInsideTheLimits) {
  // GIVEN the large robot and its workspace options
  const Robot robot = cdpr::test::large_robot();
  const PlannerOptions options = large_robot_planner_options();
  // WHEN 35 waypoints are planned
  const WaypointPlan plan = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), options);
  // THEN there are 35, inside the box and the limits, with payout = arc length + offset
  ASSERT_TRUE(plan.ok()) << plan.problem;
  ASSERT_EQ(plan.waypoints.size(), 35u);
  double min_distance_m = 1e9;
  for (std::size_t a = 0; a < plan.waypoints.size(); ++a) {
    const Waypoint& w = plan.waypoints[a];
    const Eigen::Vector3d p = w.rest.world_T_platform.position_world;
    EXPECT_GE(p.x(), 20.0);
    EXPECT_LE(p.x(), 220.0);
    EXPECT_GE(p.y(), 20.0);
    EXPECT_LE(p.y(), 200.0);
    EXPECT_GE(p.z(), options.z_min_m);
    EXPECT_LE(p.z(), options.z_max_m);
    for (int i = 0; i < kCableCount; ++i) {
      EXPECT_GE(w.rest.tension_n[i], options.min_tension_n);
      EXPECT_LE(w.rest.tension_n[i], options.max_tension_n);
      EXPECT_DOUBLE_EQ(w.payout_m[i], w.rest.arc_length_m[i] + kOffsets[i]);
    }
    for (std::size_t b = a + 1; b < plan.waypoints.size(); ++b) {
      min_distance_m = std::min(min_distance_m, (p - plan.waypoints[b].rest.world_T_platform.position_world).norm());
    }
  }
  // AND spread: no two closer than half the spacing of a regular lattice of 35 points in the box
  const double lattice_spacing_m = std::cbrt(200.0 * 180.0 * 30.0 / 35.0);
  EXPECT_GT(min_distance_m, 0.5 * lattice_spacing_m);
}

TEST(WaypointPlanner, TheSelectionOrderKeepsTheWaypointsAndDropsOnlyTheTour) {
  // GIVEN the large robot's 35-waypoint spread plan, as a tour and in selection order
  const Robot robot = cdpr::test::large_robot();
  const Eigen::Vector3d start(120, 110, 10);
  PlannerOptions tour = large_robot_planner_options(), selection = large_robot_planner_options();
  selection.order = WaypointOrder::kSelection;
  const WaypointPlan a = plan_waypoints(robot, kOffsets, start, tour);
  const WaypointPlan b = plan_waypoints(robot, kOffsets, start, selection);
  ASSERT_TRUE(a.ok()) << a.problem;
  ASSERT_TRUE(b.ok()) << b.problem;
  // THEN both visit the same waypoints; the selection order starts nearest
  // the workspace's centre and travels longer than the tour
  const auto positions = [](const WaypointPlan& plan) {
    std::vector<std::array<double, 3>> out;
    for (const Waypoint& w : plan.waypoints) {
      const Eigen::Vector3d p = w.rest.world_T_platform.position_world;
      out.push_back({p.x(), p.y(), p.z()});
    }
    return out;
  };
  std::vector<std::array<double, 3>> in_tour = positions(a), in_selection = positions(b);
  EXPECT_NE(in_tour, in_selection);
  std::sort(in_tour.begin(), in_tour.end());
  std::sort(in_selection.begin(), in_selection.end());
  EXPECT_EQ(in_tour, in_selection);
  const auto travel = [&](const WaypointPlan& plan) {
    std::vector<Pose> stops;
    for (const Waypoint& w : plan.waypoints) stops.push_back(w.rest.world_T_platform);
    std::vector<int> as_given(stops.size());
    for (std::size_t k = 0; k < stops.size(); ++k) as_given[k] = static_cast<int>(k);
    return tour_travel_m(robot, nominal_anchors(robot), Pose{start, Eigen::Quaterniond::Identity()}, stops, as_given);
  };
  EXPECT_LT(travel(a), 0.8 * travel(b));
}

TEST(WaypointPlanner, SameSeedSamePlan) {
  // GIVEN the same inputs twice
  const Robot robot = cdpr::test::large_robot();
  // WHEN planned twice
  const WaypointPlan a = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), large_robot_planner_options());
  const WaypointPlan b = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), large_robot_planner_options());
  // THEN the plans are identical
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t k = 0; k < a.waypoints.size(); ++k) EXPECT_EQ(a.waypoints[k].payout_m, b.waypoints[k].payout_m);
}

TEST(WaypointPlanner, CandidatesOverTheTensionLimitAreRejectedWithTheReason) {
  // GIVEN a maximum tension that the low, wide poses exceed
  const Robot robot = cdpr::test::large_robot();
  PlannerOptions options = large_robot_planner_options();
  options.max_tension_n = 400.0;
  options.waypoint_count = 5;
  // WHEN planned
  const WaypointPlan plan = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), options);
  // THEN some candidates are rejected naming a cable and the limit, and none chosen violates it
  ASSERT_FALSE(plan.rejected.empty());
  EXPECT_NE(plan.rejected.front().reason.find("above 400 N"), std::string::npos) << plan.rejected.front().reason;
  for (const Waypoint& w : plan.waypoints) {
    for (double tension_n : w.rest.tension_n) EXPECT_LE(tension_n, 400.0);
  }
}

TEST(WaypointPlanner, PayoutLimitsRejectFarCandidatesAndTooFewFeasibleIsAProblem) {
  // GIVEN a maximum payout that only poses near the middle respect
  const Robot robot = cdpr::test::large_robot();
  PlannerOptions options = large_robot_planner_options();
  options.max_payout_m = 160.0;
  options.waypoint_count = 200;
  // WHEN planned
  const WaypointPlan plan = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), options);
  // THEN the payout limit is named per rejected candidate and the plan says how many were feasible
  ASSERT_FALSE(plan.ok());
  EXPECT_NE(plan.problem.find("of 200 waypoints feasible"), std::string::npos) << plan.problem;
  ASSERT_FALSE(plan.rejected.empty());
  EXPECT_NE(plan.rejected.front().reason.find("payout"), std::string::npos) << plan.rejected.front().reason;
}

TEST(WaypointPlanner, DeepSagPosesAreRejectedAndNoChosenCableSagsBeyondTheLimit) {
  // GIVEN the large robot with the default sag limit, and the same with a limit only a few poses meet
  const Robot robot = cdpr::test::large_robot();
  PlannerOptions options = large_robot_planner_options();
  PlannerOptions tight = options;
  tight.max_sag_excess = 2e-3;
  tight.waypoint_count = 1;
  // WHEN both are planned
  const WaypointPlan plan = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), options);
  const WaypointPlan tight_plan = plan_waypoints(robot, kOffsets, Eigen::Vector3d(120, 110, 10), tight);
  // THEN no chosen cable is more than 2 % longer than its chord
  ASSERT_TRUE(plan.ok()) << plan.problem;
  for (const Waypoint& w : plan.waypoints) {
    for (int i = 0; i < kCableCount; ++i) {
      const double chord_m =
          (w.rest.world_T_platform.transform(robot.winches[i].attachment_platform) - robot.winches[i].anchor_world)
              .norm();
      EXPECT_LE(w.rest.arc_length_m[i], (1.0 + options.max_sag_excess) * chord_m);
    }
  }
  // AND the tight limit rejects candidates naming the cable, its arc and its chord
  const auto sagging = std::find_if(tight_plan.rejected.begin(), tight_plan.rejected.end(), [](const auto& r) {
    return r.reason.find("sag excess") != std::string::npos;
  });
  ASSERT_NE(sagging, tight_plan.rejected.end());
  EXPECT_NE(sagging->reason.find("over chord"), std::string::npos) << sagging->reason;
  EXPECT_NE(sagging->reason.find("cable "), std::string::npos) << sagging->reason;
}

TEST(WaypointPlanner, AMarginLeavingNoWorkspaceIsRefused) {
  // GIVEN a margin wider than half the footprint
  PlannerOptions options = large_robot_planner_options();
  options.margin_m = 150.0;
  // WHEN the options are checked THEN the margin is named
  EXPECT_NE(check_planner_options(cdpr::test::large_robot(), options).find("margin"), std::string::npos);
}

TEST(WaypointPlanner, OffsetsEstimatedAtARestPoseAreRecovered) {
  // GIVEN encoder readings of the modelled rest pose plus known offsets
  const Robot robot = cdpr::test::large_robot();
  const Eigen::Vector3d position(150.0, 60.0, 12.0);
  const auto rest = solve_static_pose(robot, nominal_anchors(robot), position);
  ASSERT_TRUE(rest);
  std::array<double, kCableCount> encoder_m{};
  for (int i = 0; i < kCableCount; ++i) encoder_m[i] = rest->arc_length_m[i] + kOffsets[i];
  // WHEN the offsets are estimated
  const auto offsets = estimate_payout_offsets(robot, position, encoder_m);
  // THEN they are the known ones
  ASSERT_TRUE(offsets);
  for (int i = 0; i < kCableCount; ++i) EXPECT_NEAR((*offsets)[i], kOffsets[i], 1e-9);
}

}  // namespace
}  // namespace cdpr::calibration
