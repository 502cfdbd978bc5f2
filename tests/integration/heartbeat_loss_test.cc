// The heartbeat-loss safety case, at time scale 1: cdpr-calibd (the real program,
// its own process) moves the virtual robot's winches; it is killed with
// SIGKILL in the middle of a move. The drives then hear no master
// heartbeat: after their consumer heartbeat time (0x1016, 500 ms) they
// quick-stop on the quick-stop ramp (0x6085, 2 m/s^2), so the platform
// must come to rest within the heartbeat time plus the braking distance
// (plus its own settling lag), not drift on to the waypoint.

#include <signal.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>
#include <vector>

#include "daemon_process.h"
#include "drivers/pose/pose_stream_source.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kConsumerHeartbeatS = 0.5;
constexpr double kCableSpeedMps = 2.0;       // profile velocity of the longest cable
constexpr double kQuickStopDecelMps2 = 2.0;  // 0x6085
constexpr double kSettleLagS = 0.2;          // the platform's time constant in the physics

std::string daemon_config(const std::string& dir, const virtual_robot::VirtualRobot& robot) {
  return "robot = \"" + dir + "/robot/robot.toml\"\n"
         "[store]\nstate_dir = \"" + dir + "/state\"\n"
         "[control]\nsocket = \"" + dir + "/control\"\n"
         "[winches]\nendpoint = \"" + robot.can_endpoint() + "\"\n"
         "[winches.drive]\nconsumer_heartbeat_ms = 500\nprofile_velocity_mps = 2.0\n"
         "profile_acceleration_mps2 = 1.0\nprofile_deceleration_mps2 = 1.0\nquick_stop_deceleration_mps2 = 2.0\n"
         "[load_cell]\nendpoint = \"" + robot.modbus_endpoint() + "\"\n"
         "[pose]\nendpoint = \"" + robot.pose_endpoint() + "\"\n"
         "[button]\nkind = \"none\"\n";
}

struct PosePoint {
  double t_s;
  Eigen::Vector3d position;
};

TEST(HeartbeatLoss, DrivesStopWithinHeartbeatTimePlusBrakingAfterKill9) {
  // GIVEN the large virtual robot at time scale 1 and cdpr-calibd as its own process
  virtual_robot::VirtualRobotOptions options = large_robot_acceptance_options();
  options.time_scale = 1.0;
  options.noise_scale = 0.0;  // the stop distance, not the noise, is measured
  // The winches' stop is measured through the platform, so the platform
  // follows its rest pose without sway: critically damped, lagging a moving
  // rest by 2 / w = kSettleLagS / 2, inside the lag the bound allows (a
  // swaying platform would hide where the cables stopped).
  options.physics.damping_ratio = 1.0;
  options.physics.sway_period_s = M_PI * kSettleLagS / 2.0;
  char pattern[] = "/tmp/cdpr-heartbeat-XXXXXX";
  const std::string dir = mkdtemp(pattern);
  options.dir = dir + "/robot";
  std::filesystem::create_directories(options.dir);
  auto created = virtual_robot::VirtualRobot::create(options);
  ASSERT_TRUE(created) << created.error();
  std::unique_ptr<virtual_robot::VirtualRobot> robot = std::move(*created);
  std::atomic<bool> stop_robot{false};
  std::thread robot_thread([&] { robot->run(stop_robot); });
  std::ofstream(dir + "/cdpr-calibd.toml") << daemon_config(dir, *robot);
  ChildProcess daemon({built_program("src/cdpr-calibd"), "--config", dir + "/cdpr-calibd.toml"},
                      dir + "/daemon.log");
  drivers::MonotonicClock clock;
  drivers::pose::PoseStreamSource pose(robot->pose_endpoint(), clock);
  ASSERT_TRUE(pose.open().ok());
  const auto ask = [&](const std::string& request) { return ask_daemon(dir + "/control", request); };
  for (int i = 0; i < 100 && !std::filesystem::exists(dir + "/control"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(ask("start")["ok"].boolean()) << "daemon log: " << dir << "/daemon.log";

  // WHEN the first move has run 3 s (the longest cable at full speed)
  std::vector<PosePoint> track;
  const auto t0 = Clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  const auto sample = [&] {
    (void)pose.update(0);
    if (auto p = pose.latest()) {
      const Eigen::Vector3d x(p->platform_world.x, p->platform_world.y, p->platform_world.z);
      if (track.empty() || (track.back().position - x).norm() > 0.0 || seconds() - track.back().t_s > 0.05) {
        track.push_back({seconds(), x});
      }
    }
  };
  double move_started_s = -1.0;
  while (seconds() < 60.0) {
    sample();
    if (move_started_s < 0 && ask("status")["state"].string() == "move") move_started_s = seconds();
    if (move_started_s >= 0 && seconds() - move_started_s >= 3.0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_GE(move_started_s, 0.0) << "no move within 60 s; daemon log: " << dir << "/daemon.log";
  ASSERT_FALSE(track.empty());
  const PosePoint before = track.size() > 50 ? track[track.size() - 50] : track.front();
  const PosePoint at_kill = track.back();
  const double platform_speed_mps = (at_kill.position - before.position).norm() / (at_kill.t_s - before.t_s);
  daemon.signal(SIGKILL);
  ASSERT_EQ(daemon.wait_exit(std::chrono::seconds(5)), 128 + SIGKILL);
  const double kill_s = seconds();
  // AND the platform is watched for 6 s
  while (seconds() - kill_s < 6.0) {
    sample();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stop_robot.store(true);
  robot_thread.join();

  // THEN it came to rest: the last 2 s moved less than 1 cm
  const PosePoint& last = track.back();
  PosePoint two_s_before = last;
  for (const PosePoint& p : track) {
    if (p.t_s <= last.t_s - 2.0) two_s_before = p;
  }
  EXPECT_LT((last.position - two_s_before.position).norm(), 0.01);
  // AND it went no further than the speed it had for the heartbeat time and
  // its settling lag, plus the braking distance
  double rest_s = kill_s;
  for (const PosePoint& p : track) {
    if (p.t_s >= kill_s && (p.position - last.position).norm() > 0.01) rest_s = p.t_s;
  }
  const double travelled_m = (last.position - at_kill.position).norm();
  const double braking_s = kCableSpeedMps / kQuickStopDecelMps2;
  // 0.1 s more for the scheduling of the virtual robot's thread on a shared test machine.
  const double bound_m = platform_speed_mps * (kConsumerHeartbeatS + kSettleLagS + braking_s / 2.0 + 0.1) + 0.05;
  std::printf("heartbeat loss at time scale 1: platform at %.2f m/s when killed, travelled %.3f m after the kill, "
              "within 1 cm of rest %.2f s after it (bound %.3f m; heartbeat %.1f s + braking %.1f s)\n",
              platform_speed_mps, travelled_m, rest_s - kill_s, bound_m, kConsumerHeartbeatS, braking_s);
  EXPECT_GT(platform_speed_mps, 0.1) << "the platform was not moving when the daemon was killed";
  EXPECT_LT(travelled_m, bound_m);
  EXPECT_LT(rest_s - kill_s, kConsumerHeartbeatS + braking_s + 5 * kSettleLagS);
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cdpr::integration
