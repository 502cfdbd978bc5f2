// The daemon's plan, made from the nominal robot, must be one the TRUE robot
// can follow: at every waypoint's payouts the true heavy cables have a taut
// rest pose near the planned one. A plan that is not (a cable commanded far
// too long, a pose near a singular corner) makes the platform hang wherever
// it can and the sample describes a pose nobody planned, or none at all.

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "sim/equilibrium.h"
#include "src/calibration/waypoint_planner.h"
#include "src/daemon/daemon_config.h"
#include "virtual-robot/robot_physics.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

// Both ways of picking the waypoints from the feasible candidates: spread
// evenly (the default) and informative (A-optimal, crowding towards the
// workspace's edges, where a wrong plan would show first).
class PlannedWaypoints : public ::testing::TestWithParam<calibration::WaypointSelection> {};

TEST_P(PlannedWaypoints, TheTrueLargeRobotRestsNearEveryWaypointPlannedFromNominalAnchors) {
  // GIVEN the virtual robot of the full calibration test (large, nominal anchors 0.3 m off), at rest where it starts
  // WHEN the daemon (default settings, but the selection) estimates the offsets there and plans
  const auto planned = plan_acceptance_robot(GetParam());
  ASSERT_TRUE(planned);
  const calibration::WaypointPlan& plan = planned->plan;
  ASSERT_TRUE(plan.ok()) << plan.problem;
  ASSERT_EQ(static_cast<int>(plan.waypoints.size()), daemon::default_daemon_config().calibrator.planner.waypoint_count);
  const sim::TrueRobot& truth = planned->data.true_robot;
  const Eigen::Vector3d& start_world = planned->start_world;

  // THEN the virtual robot's true physics, driven through the waypoints in order, rests within 1 m of
  // each planned pose
  virtual_robot::PhysicsOptions physics_options;
  physics_options.winch_speed_mps = 5.0;  // fewer equilibrium solves per move; same continuation
  auto physics = virtual_robot::RobotPhysics::at_rest(truth, start_world, physics_options);
  ASSERT_TRUE(physics) << physics.error();
  for (std::size_t k = 0; k < plan.waypoints.size(); ++k) {
    const calibration::Waypoint& waypoint = plan.waypoints[k];
    for (int i = 0; i < kCableCount; ++i) physics->set_target(i, waypoint.payout_m[i]);
    for (int step = 0; step < 20000 && !(physics->at_target(0) && physics->at_target(1) && physics->at_target(2) &&
                                         physics->at_target(3));
         ++step) {
      physics->advance(0.01);
    }
    for (int step = 0; step < 600; ++step) physics->advance(1.0);  // the sway dies out: about 12 / (zeta w)
    const Eigen::Vector3d& planned = waypoint.rest.world_T_platform.position_world;
    const double miss_m = (physics->pose().position_world - planned).norm();
    EXPECT_LT(miss_m, 1.0) << "waypoint " << k << " planned at (" << planned.transpose() << "), arc lengths "
                           << waypoint.rest.arc_length_m[0] << ", " << waypoint.rest.arc_length_m[1] << ", "
                           << waypoint.rest.arc_length_m[2] << ", " << waypoint.rest.arc_length_m[3] << " m; "
                           << physics->failed_solves() << " failed equilibrium solves so far";
  }
}

INSTANTIATE_TEST_SUITE_P(Selection, PlannedWaypoints,
                         ::testing::Values(calibration::WaypointSelection::kSpread,
                                           calibration::WaypointSelection::kInformative),
                         [](const ::testing::TestParamInfo<calibration::WaypointSelection>& info) {
                           return info.param == calibration::WaypointSelection::kSpread ? "Spread" : "Informative";
                         });

}  // namespace
}  // namespace cdpr::integration
