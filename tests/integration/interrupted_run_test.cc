// A daemon killed with SIGKILL mid-run, as real processes against the
// virtual robot: the run marker it kept says where it was, a restarted
// daemon (the lock died with the first) reports "run interrupted at <time>,
// waypoint k of n" in its log and its status until the next start.

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <utility>

#include "slowdown.h"
#include "virtual_robot_process.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

// Found in 15abf05 failing 2 of 6 runs without "winch 0 drive 1:
// operational, quick stop active" after the restart: the status was read
// before the restarted daemon had configured the nodes (NMT unknown, "not
// configured"), since the test waited on the wall clock for the drives'
// quick stop alone, which their first PDO shows. On a starved robot the
// daemon gets too little of the robot's time for that; the test now waits
// for everything it then checks, on the robot's clock, and starves the
// robot itself.
TEST(InterruptedRun, ADaemonKilledMidRunIsReportedAfterRestartUntilTheNextStart) {
  // GIVEN the virtual small robot and a daemon calibrating it, at waypoint 2 or later
  VirtualRobotProcess rig;
  auto first = rig.start_daemon("first");
  ASSERT_TRUE(wait_until([&] { return rig.answers(); }, slowed(30s))) << first->log();
  std::this_thread::sleep_for(1s);  // the CANopen nodes' first heartbeats
  ASSERT_TRUE(rig.ask("start")["ok"].boolean()) << first->log();
  calibctl::JsonValue status;
  ASSERT_TRUE(rig.wait_until_robot(
      [&] {
        status = rig.ask("status");
        return status["waypoint"].integer() >= 2 || !status["running"].boolean();
      },
      slowed(120s)))
      << first->log();
  ASSERT_TRUE(status["running"].boolean()) << status["reason"].string() << "\n" << first->log();
  const int waypoint_seen = status["waypoint"].integer();
  const int waypoints = status["waypoints"].integer();

  // WHEN the daemon is killed with SIGKILL and started again
  first->signal(SIGKILL);
  ASSERT_EQ(first->wait_exit(slowed(10s)), std::optional<int>(128 + SIGKILL));
  EXPECT_TRUE(std::filesystem::exists(rig.state_dir + "/run-in-progress.toml"));
  // (Restarted after the drives' consumer heartbeat time, 500 ms of the
  // robot's clock, which runs slower when the robot is starved: they quick-stop on their own.)
  RobotDeadline(rig.robot_clock(), slowed(1s)).wait();
  // The robot starved of CPU from the restart on (its clock stands still,
  // then runs at a tenth of its speed): a loaded machine must not change the
  // verdict.
  rig.starve_robot(true);
  auto second = rig.start_daemon("second");
  ASSERT_TRUE(wait_until([&] { return rig.answers(); }, slowed(30s))) << second->log();

  // THEN its status and log say the run was interrupted, at which waypoint of how many
  const std::string interrupted = rig.ask("status")["interrupted"].string();
  std::printf("after restart: %s\n", interrupted.c_str());
  EXPECT_EQ(interrupted.rfind("run interrupted at 20", 0), 0u) << interrupted;
  const std::size_t at = interrupted.find(", waypoint ");
  ASSERT_NE(at, std::string::npos) << interrupted;
  const int waypoint_reported = std::atoi(interrupted.c_str() + at + 11);
  EXPECT_GE(waypoint_reported, waypoint_seen) << interrupted;
  EXPECT_LE(waypoint_reported, waypoint_seen + 1) << interrupted;  // it may have moved on before the kill
  EXPECT_NE(interrupted.find(" of " + std::to_string(waypoints) + " ("), std::string::npos) << interrupted;
  EXPECT_NE(second->log().find("cdpr-calibd: run interrupted at "), std::string::npos) << second->log();
  // AND calibctl status shows it to the operator
  ChildProcess calibctl({built_program("tools/calibctl/calibctl"), "--socket", rig.socket, "status"},
                        rig.dir + "/calibctl.log");
  EXPECT_EQ(calibctl.wait_exit(slowed(30s)), std::optional<int>(0));
  EXPECT_NE(calibctl.log().find("\n  interrupted: run interrupted at 20"), std::string::npos) << calibctl.log();
  std::optional<VirtualRobotProcess::StarvedRobot> starved(std::in_place, rig);
  // AND the drives, which quick-stopped on their own when the first daemon's
  // heartbeat stopped (0x1016, 0x6007), are listed in quick stop active,
  // once the restarted daemon has configured every node and heard it
  int drives_in_quick_stop = 0, nodes_configured = 0;
  EXPECT_TRUE(rig.wait_until_robot(
      [&] {
        drives_in_quick_stop = nodes_configured = 0;
        for (const calibctl::JsonValue& node : rig.ask("status")["nodes"].array()) {
          drives_in_quick_stop += node["role"].string() == "drive" && node["cia402"].string() == "quick stop active";
          nodes_configured += node["configured"].boolean() && node["nmt"].string() == "operational";
        }
        return drives_in_quick_stop == 4 && nodes_configured == 8;
      },
      slowed(10s)))
      << drives_in_quick_stop << " drives in quick stop active, " << nodes_configured
      << " nodes configured and operational; status: " << rig.ask("status")["nodes"].array().size() << " nodes";
  ChildProcess nodes({built_program("tools/calibctl/calibctl"), "--socket", rig.socket, "status"},
                     rig.dir + "/calibctl-nodes.log");
  EXPECT_EQ(nodes.wait_exit(slowed(30s)), std::optional<int>(0));
  EXPECT_NE(nodes.log().find("\n    winch 0 drive 1: operational, quick stop active"), std::string::npos) << nodes.log();
  std::printf("calibctl status after the restart:\n%s", nodes.log().c_str());

  // AND WHEN a new run starts THEN the report is gone; once it is aborted the marker is removed
  ASSERT_TRUE(rig.ask("start")["ok"].boolean()) << second->log();
  EXPECT_EQ(rig.ask("status")["interrupted"].string(), "");
  EXPECT_TRUE(rig.ask("abort")["ok"].boolean());
  EXPECT_TRUE(rig.wait_until_robot(
      [&] { return !std::filesystem::exists(rig.state_dir + "/run-in-progress.toml"); }, slowed(10s)));
  starved.reset();
  second->signal(SIGTERM);
  EXPECT_EQ(second->wait_exit(slowed(30s)), std::optional<int>(0)) << second->log();
}

}  // namespace
}  // namespace cdpr::integration
