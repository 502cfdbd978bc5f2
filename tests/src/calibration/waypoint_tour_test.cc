#include "src/calibration/waypoint_tour.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "../../solver/model/test_robots.h"
#include "solver/model/static_pose.h"

namespace cdpr::calibration {
namespace {

TEST(WaypointTour, TwoOptNeverLengthensTheNearestNeighbourTourAndVisitsEachOnce) {
  // GIVEN the large robot and a scatter of stops
  const Robot robot = cdpr::test::large_robot();
  const auto anchors = nominal_anchors(robot);
  std::vector<Pose> stops;
  for (int k = 0; k < 30; ++k) {
    stops.push_back(Pose{Eigen::Vector3d(30.0 + (k * 37) % 180, 30.0 + (k * 53) % 160, 5.0 + (k * 7) % 30),
                         Eigen::Quaterniond::Identity()});
  }
  const Pose start{Eigen::Vector3d(120, 110, 5), Eigen::Quaterniond::Identity()};
  // WHEN ordered by nearest neighbour alone and with 2-opt
  const std::vector<int> nn = tour_order(robot, anchors, start, stops, false);
  const std::vector<int> opt = tour_order(robot, anchors, start, stops, true);
  // THEN both visit every stop once and 2-opt is no longer
  std::vector<int> sorted = opt;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < 30; ++k) EXPECT_EQ(sorted[k], k);
  EXPECT_EQ(nn.size(), 30u);
  EXPECT_LE(tour_travel_m(robot, anchors, start, stops, opt), tour_travel_m(robot, anchors, start, stops, nn) + 1e-9);
}

TEST(WaypointTour, TravelIsTheLargestCableLengthChange) {
  // GIVEN the large robot; WHEN the platform rises 1 m straight up
  const Robot robot = cdpr::test::large_robot();
  const auto anchors = nominal_anchors(robot);
  const Pose a{Eigen::Vector3d(120, 110, 10), Eigen::Quaterniond::Identity()};
  Pose b = a;
  b.position_world.z() += 1.0;
  // THEN the travel is positive, below 1 m and symmetric
  const double travel = winch_travel_m(robot, anchors, a, b);
  EXPECT_GT(travel, 0.0);
  EXPECT_LT(travel, 1.0);
  EXPECT_DOUBLE_EQ(travel, winch_travel_m(robot, anchors, b, a));
}

}  // namespace
}  // namespace cdpr::calibration
