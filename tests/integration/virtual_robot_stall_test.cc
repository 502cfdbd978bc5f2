// The virtual robot starved of CPU: at time scale 20 a 0.5 s stall of its
// process is 10 s of robot time, a whole move. It must still hang the
// platform on four cables through the moves, as when it runs on time: a
// load cell that read 0 N mid-move (a rest pose solved with its cable
// slack, from a start far from the new one) failed daemon runs on a loaded
// test machine with "tension out of limits".

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "drive_commands.h"
#include "drivers/clock/monotonic_clock.h"
#include "drivers/pose/pose_stream_source.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

constexpr int kStallMoves = 10;

std::unique_ptr<virtual_robot::VirtualRobot> acceptance_robot(const std::string& dir) {
  virtual_robot::VirtualRobotOptions options = large_robot_acceptance_options();
  options.dir = dir;
  std::filesystem::create_directories(dir);
  auto created = virtual_robot::VirtualRobot::create(options);
  EXPECT_TRUE(created) << created.error();
  if (!created) return nullptr;
  for (int i = 0; i < kCableCount; ++i) enable_profile_position((*created)->nodes().drive(i), 0);
  return std::move(*created);
}

// Sends the drives to `target_m` together (each profile scaled by its share
// of the longest move, as the winch bank does), runs the move and 2 s more
// in `steps` equal steps of simulated time, and ends the set-point handshake.
void move(virtual_robot::VirtualRobot& robot, const std::array<double, kCableCount>& target_m, int steps,
          hal::TimeUs& now_us) {
  const double m_per_count = robot.options().nodes.drive_m_per_count;
  double longest_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) longest_m = std::max(longest_m, std::abs(target_m[i] - robot.physics().payout_m(i)));
  for (int i = 0; i < kCableCount; ++i) {
    virtual_robot::Cia402Device& drive = robot.nodes().drive(i);
    const double share = std::abs(target_m[i] - robot.physics().payout_m(i)) / longest_m;
    start_move(drive, static_cast<std::int32_t>(std::lround(target_m[i] / m_per_count)),
               share * kProfileVelocityMps / m_per_count, share * kProfileAccelerationMps2 / m_per_count, now_us);
    finish_move(drive, now_us);
  }
  const double move_s = longest_m / kProfileVelocityMps + kProfileVelocityMps / kProfileAccelerationMps2 + 2.0;
  for (int k = 0; k < steps; ++k) robot.advance(move_s / steps);
  std::vector<drivers::can::CanFrame> frames;
  for (int k = 0; k < 2; ++k) robot.nodes().poll(now_us += 1'000'000, frames);  // acknowledged, then cleared
}

TEST(VirtualRobotStall, MovesEachInOneStepHangOnFourCablesAsInShortSteps) {
  // GIVEN the acceptance robot, twice, and the first waypoints of the daemon's plan
  const auto planned = plan_acceptance_robot(calibration::WaypointSelection::kSpread);
  ASSERT_TRUE(planned);
  ASSERT_TRUE(planned->plan.ok()) << planned->plan.problem;
  char pattern[] = "/tmp/cdpr-stall-XXXXXX";
  const std::string dir = mkdtemp(pattern);
  auto on_time = acceptance_robot(dir + "/on-time");
  auto starved = acceptance_robot(dir + "/starved");
  ASSERT_TRUE(on_time && starved);

  for (int k = 0; k < kStallMoves; ++k) {
    // WHEN one runs each move in 400 steps and the other in a single step
    const std::array<double, kCableCount>& target_m = planned->plan.waypoints[k].payout_m;
    hal::TimeUs now_a = 0, now_b = 0;
    move(*on_time, target_m, 400, now_a);
    move(*starved, target_m, 1, now_b);

    // THEN the starved one never hung on three cables and rests where the other does
    const virtual_robot::RobotPhysics &a = on_time->physics(), &b = starved->physics();
    ASSERT_EQ(a.slack_solves() + a.failed_solves(), 0) << "move " << k;
    EXPECT_EQ(b.slack_solves(), 0) << "move " << k;
    EXPECT_EQ(b.failed_solves(), 0) << "move " << k;
    for (int i = 0; i < kCableCount; ++i) {
      EXPECT_NEAR(b.payout_m(i), target_m[i], 1e-4) << "move " << k << ", cable " << i;
      EXPECT_NEAR(b.rest().cables[i].tension_n, a.rest().cables[i].tension_n, 1e-3 * a.rest().cables[i].tension_n)
          << "move " << k << ", cable " << i;
    }
    EXPECT_LT((b.rest().world_T_platform.position_world - a.rest().world_T_platform.position_world).norm(), 1e-3)
        << "move " << k;
  }
  on_time.reset();
  starved.reset();
  std::filesystem::remove_all(dir);
}

TEST(VirtualRobotStall, AStarvedPassSimulatesAtMostItsShareOfSolves) {
  // GIVEN the acceptance robot (time scale 20; 20/3 in the sanitizer build)
  const auto planned = plan_acceptance_robot(calibration::WaypointSelection::kSpread);
  ASSERT_TRUE(planned);
  char pattern[] = "/tmp/cdpr-stall-XXXXXX";
  const std::string dir = mkdtemp(pattern);
  auto robot = acceptance_robot(dir + "/robot");
  ASSERT_TRUE(robot);
  // AND a pose stream client with the robot's first pose
  drivers::MonotonicClock clock;
  drivers::pose::PoseStreamSource pose(robot->pose_endpoint(), clock);
  ASSERT_TRUE(pose.open().ok());
  for (int k = 0; k < 100 && !pose.latest(); ++k) {
    robot->run_once(10'000);
    (void)pose.update(0);
  }
  ASSERT_TRUE(pose.latest());
  const hal::TimeUs first_stamp_us = pose.latest()->source_time_us;
  // AND its drives starting the first move from rest (after the passes the
  // first pose took, whose number the machine's load decides)
  const std::array<double, kCableCount>& target_m = planned->plan.waypoints.front().payout_m;
  const double m_per_count = robot->options().nodes.drive_m_per_count;
  for (int i = 0; i < kCableCount; ++i) {
    start_move(robot->nodes().drive(i), static_cast<std::int32_t>(std::lround(target_m[i] / m_per_count)),
               kProfileVelocityMps / m_per_count, kProfileAccelerationMps2 / m_per_count, 0);
  }
  std::array<double, kCableCount> before_m{};
  for (int i = 0; i < kCableCount; ++i) before_m[i] = robot->physics().payout_m(i);

  // WHEN its process gets no CPU for 0.3 s (6 s of robot time at 20x) and then one pass
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  robot->run_once(0);
  const double gap_s = 0.3 * robot->time_scale();
  ASSERT_TRUE(pose.update(1'000'000).ok());

  // THEN that pass simulated only kMaxSolvesPerPass equilibrium intervals
  // (0.2 s: 2 cm from rest at 1 m/s^2; the bound allows twice the time),
  // not the gap (about 10 m in 6 s)
  const double simulated_s = virtual_robot::VirtualRobot::kMaxSolvesPerPass *
                             robot->options().physics.equilibrium_interval_s;
  ASSERT_GT(gap_s, 4.0 * simulated_s);
  const double farthest_m = 0.5 * kProfileAccelerationMps2 * (2.0 * simulated_s) * (2.0 * simulated_s);
  double moved_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) moved_m = std::max(moved_m, std::abs(robot->physics().payout_m(i) - before_m[i]));
  EXPECT_GT(moved_m, 0.0);
  EXPECT_LT(moved_m, farthest_m);
  // AND the robot time left out is counted: the gap less what the passes simulated
  EXPECT_GT(robot->robot_time_lost_s(), gap_s - 2.0 * simulated_s);
  // AND the pose stamps run on the robot's clock, not the gap's: the
  // platform's speed over them is its own
  EXPECT_LT(1e-6 * static_cast<double>(pose.latest()->source_time_us - first_stamp_us), gap_s / 2.0);
  robot.reset();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cdpr::integration
