#include "src/calibration/waypoint_sequence.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../../solver/model/test_robots.h"
#include "large_robot_planner_options.h"

namespace cdpr::calibration {
namespace {

TEST(WaypointSequence, AFailedReSolveFallsBackToTheNextSpreadWaypoint) {
  // GIVEN the sequential strategy on the large robot
  const Robot robot = cdpr::test::large_robot();
  SequentialOptions sequential;
  sequential.max_count = 12;
  sequential.resolve = [](const Robot&, const std::vector<Sample>&, const CalibrationOptions&) {
    CalibrationResult failed;
    failed.message = "no start converged";
    return failed;
  };
  PlannerOptions planner = large_robot_planner_options();
  planner.grid_xy = 4;
  planner.grid_z = 2;
  WaypointSequence sequence;
  ASSERT_EQ(sequence.start(robot, {}, Eigen::Vector3d(120, 110, 10), planner, WaypointStrategy::kSequential,
                           sequential, 0),
            "");
  // WHEN every re-solve fails
  std::vector<const Waypoint*> visited;
  int fallbacks = 0;
  hal::TimeUs now_us = 0;
  while (const Waypoint* w = sequence.current()) {
    ASSERT_LT(visited.size(), 40u);
    EXPECT_EQ(std::count(visited.begin(), visited.end(), w), 0) << "visited twice";
    visited.push_back(w);
    Sample sample;
    sample.id = static_cast<int>(visited.size());
    sample.position_world = w->rest.world_T_platform.position_world;
    sample.world_R_platform = w->rest.world_T_platform.world_R_platform;
    now_us += 60'000'000;
    sequence.sampled(sample, now_us);
    if (sequence.remark().find("failed: next waypoint in spread order") != std::string::npos) ++fallbacks;
  }
  // THEN the run goes on to max_count, each waypoint after the initial set
  // the next unused one in spread order, and the remark says so
  EXPECT_EQ(static_cast<int>(visited.size()), sequential.max_count) << sequence.stop_reason();
  EXPECT_GE(fallbacks, 1);
}

}  // namespace
}  // namespace cdpr::calibration
