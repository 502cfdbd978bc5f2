// The virtual robot's mechanics: winches move at their profile speed and the
// platform settles into the true equilibrium of the new cable lengths.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "sim/equilibrium.h"
#include "sim/presets.h"
#include "virtual-robot/robot_physics.h"

namespace cdpr::virtual_robot {
namespace {

TEST(RobotPhysics, PlatformSettlesIntoTheEquilibriumOfTheCommandedPayouts) {
  // GIVEN the large robot at rest in the middle of its workspace, offsets nonzero
  sim::TrueRobot robot = sim::preset_spec(sim::Preset::kLarge).robot;
  robot.encoder_offset_m = {1.0, -2.0, 0.5, 3.0};
  const Eigen::Vector3d start(120.0, 110.0, 17.0);
  auto physics = RobotPhysics::at_rest(robot, start, PhysicsOptions{});
  ASSERT_TRUE(physics) << physics.error();
  EXPECT_LT((physics->pose().position_world - start).norm(), 1e-6);
  // WHEN cable 0 is paid out by 2 m and cable 2 hauled in by 2 m, and the sway has died out
  const double p0 = physics->payout_m(0), p2 = physics->payout_m(2);
  physics->set_target(0, p0 + 2.0);
  physics->set_target(2, p2 - 2.0);
  for (int k = 0; k < 2000; ++k) physics->advance(0.01);
  for (int k = 0; k < 1000; ++k) physics->advance(1.0);
  // THEN the winches are there, and the platform rests where the true equilibrium of those payouts is
  EXPECT_TRUE(physics->at_target(0) && physics->at_target(2));
  EXPECT_EQ(physics->failed_solves(), 0);
  std::array<double, kCableCount> unstretched{};
  for (int i = 0; i < kCableCount; ++i) unstretched[i] = physics->payout_m(i) - robot.encoder_offset_m[i];
  sim::SolverOptions options;
  options.segments = PhysicsOptions{}.segments;
  const auto expected = sim::solve_forward_equilibrium(robot, unstretched, physics->pose(), options);
  ASSERT_TRUE(expected);
  EXPECT_GT((physics->pose().position_world - start).norm(), 0.5);  // it did move
  EXPECT_LT((physics->pose().position_world - expected->world_T_platform.position_world).norm(), 1e-6);
  EXPECT_NEAR(physics->tension_n(0), expected->cables[0].tension_n, 1e-3);
}

TEST(RobotPhysics, HeavyCablePaidOutPastItsRestLengthHangsInALoopThatStillPulls) {
  // GIVEN the large robot at rest in the half of its workspace that cables 1-3 alone can hold
  sim::TrueRobot robot = sim::preset_spec(sim::Preset::kLarge).robot;
  robot.encoder_offset_m = {1.0, -2.0, 0.5, 3.0};
  const Eigen::Vector3d start(150.0, 140.0, 17.0);
  auto physics = RobotPhysics::at_rest(robot, start, PhysicsOptions{});
  ASSERT_TRUE(physics) << physics.error();
  const double p0 = physics->payout_m(0);
  const double t0 = physics->tension_n(0);
  // WHEN cable 0 is paid out 30 m and the sway has died out
  physics->set_target(0, p0 + 30.0);
  for (int k = 0; k < 2000; ++k) physics->advance(0.01);
  for (int k = 0; k < 1000; ++k) physics->advance(1.0);
  // THEN it is not slack: its deep loop pulls with part of its own weight, far less than before
  EXPECT_EQ(physics->failed_solves(), 0);
  EXPECT_FALSE(physics->rest().cables[0].slack);
  EXPECT_GT(physics->tension_n(0), 20.0);
  EXPECT_LT(physics->tension_n(0), 0.5 * t0);
  // AND the platform rests near, not at, where the other three would hold it alone
  std::array<double, kCableCount> unstretched{};
  for (int i = 0; i < kCableCount; ++i) unstretched[i] = physics->payout_m(i) - robot.encoder_offset_m[i];
  sim::SolverOptions options;
  options.segments = PhysicsOptions{}.segments;
  const auto three = sim::solve_forward_equilibrium(robot, unstretched, physics->pose(), options, {true});
  ASSERT_TRUE(three) << three.error().message;
  EXPECT_EQ(three->cables[0].tension_n, 0.0);
  const double apart_m = (physics->pose().position_world - three->world_T_platform.position_world).norm();
  EXPECT_GT(apart_m, 0.01);
  EXPECT_LT(apart_m, 1.0);
  // WHEN cable 0 is hauled back in
  physics->set_target(0, p0);
  for (int k = 0; k < 2000; ++k) physics->advance(0.01);
  for (int k = 0; k < 1000; ++k) physics->advance(1.0);
  // THEN the platform is back at the start with the tension it had
  EXPECT_EQ(physics->failed_solves(), 0);
  EXPECT_NEAR(physics->tension_n(0), t0, 1e-3);
  EXPECT_LT((physics->pose().position_world - start).norm(), 1e-6);
}

TEST(RobotPhysics, PlatformSwaysAfterAMoveWithTheGeometricPeriodAndLightDamping) {
  // GIVEN the large robot at rest in the middle of its workspace
  const sim::TrueRobot robot = sim::preset_spec(sim::Preset::kLarge).robot;
  PhysicsOptions options;
  auto physics = RobotPhysics::at_rest(robot, Eigen::Vector3d(120.0, 110.0, 17.0), options);
  ASSERT_TRUE(physics);
  // WHEN two cables move by 2 m at the profile speed, and the platform's x is followed afterwards
  physics->set_target(0, physics->payout_m(0) + 2.0);
  physics->set_target(2, physics->payout_m(2) - 2.0);
  while (!(physics->at_target(0) && physics->at_target(2))) physics->advance(0.01);
  physics->advance(0.1);  // the last solve
  const double rest_x = physics->rest().world_T_platform.position_world.x();
  std::vector<double> crossings, peaks;
  double previous = physics->pose().position_world.x() - rest_x, peak = 0.0;
  for (int k = 0; k < 20000; ++k) {
    physics->advance(0.01);
    const double e = physics->pose().position_world.x() - rest_x;
    peak = std::max(peak, std::abs(e));
    if ((e > 0.0) != (previous > 0.0)) {
      crossings.push_back(0.01 * k);
      peaks.push_back(peak);
      peak = 0.0;
    }
    previous = e;
  }
  // THEN it swings about the rest pose with a period of several seconds, losing a few % per period
  ASSERT_GE(crossings.size(), 10u);
  const double period_s = 2.0 * (crossings.back() - crossings[1]) / static_cast<double>(crossings.size() - 2);
  EXPECT_NEAR(period_s, physics->sway_period_s(), 0.02 * period_s);
  EXPECT_GT(period_s, 3.0);
  EXPECT_LT(period_s, 30.0);
  const double decay_per_period = std::pow(peaks.back() / peaks[2], 2.0 / static_cast<double>(peaks.size() - 3));
  EXPECT_NEAR(decay_per_period, std::exp(-2.0 * M_PI * options.damping_ratio), 0.03);
}

}  // namespace
}  // namespace cdpr::virtual_robot

namespace cdpr::virtual_robot {
namespace {

TEST(RobotPhysics, FindsTheNewRestPoseAfterAMoveThroughSlackCables) {
  // GIVEN the large robot at rest in the middle, and the payouts of a rest pose 60 m away
  const sim::TrueRobot robot = sim::preset_spec(sim::Preset::kLarge).robot;
  auto physics = RobotPhysics::at_rest(robot, Eigen::Vector3d(120.0, 110.0, 17.0), PhysicsOptions{});
  ASSERT_TRUE(physics);
  const auto goal = sim::solve_equilibrium(robot, Eigen::Vector3d(60.0, 80.0, 30.0), 0.0);
  ASSERT_TRUE(goal);
  // WHEN every winch runs there at the same speed (so cables go slack on the way) and time passes
  for (int i = 0; i < kCableCount; ++i) physics->set_target(i, goal->cables[i].payout_m);
  for (int k = 0; k < 10000; ++k) physics->advance(0.01);
  for (int k = 0; k < 1000; ++k) physics->advance(1.0);  // the sway dies out
  // THEN the platform rests at that pose
  EXPECT_LT((physics->pose().position_world - goal->world_T_platform.position_world).norm(), 1e-4);
}

}  // namespace
}  // namespace cdpr::virtual_robot
