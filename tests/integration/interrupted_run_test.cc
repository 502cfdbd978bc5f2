// A daemon killed with SIGKILL mid-run, as real processes against the
// virtual robot: the run marker it kept says where it was, a restarted
// daemon (the lock died with the first) reports "run interrupted at <time>,
// waypoint k of n" in its log and its status until the next start.

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "calibctl/control_client.h"
#include "calibctl/json_value.h"
#include "daemon_process.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

calibctl::JsonValue ask(const std::string& socket, const std::string& request) {
  calibctl::ControlClient client;
  std::string error, response;
  if (!client.connect(socket, error) || !client.request(request, response, error, 30'000)) return {};
  auto value = calibctl::JsonValue::parse(response);
  return value ? *value : calibctl::JsonValue{};
}

std::string file_value(const std::string& path, const std::string& key) {
  std::ifstream file(path);
  std::string line;
  while (std::getline(file, line)) {
    if (line.rfind(key + " = ", 0) == 0) return line.substr(key.size() + 3);
  }
  return {};
}

// The small robot's limits and the demo's equilibrium settings (the physics
// runs 20x faster than real time).
std::string small_robot_config(const std::string& dir, const std::string& modbus_port) {
  const std::string path = dir + "/cdpr-calibd.toml";
  std::ofstream(path) << "robot = \"" << dir << "/robot/robot.toml\"\n[store]\nstate_dir = \"" << dir
                      << "/state\"\n[control]\nsocket = \"" << dir << "/control\"\n[winches]\nendpoint = \"unix:"
                      << dir << "/robot/can.sock\"\nheartbeat_timeout_ms = 3000\n[load_cell]\nendpoint = "
                      << "\"tcp:127.0.0.1:" << modbus_port << "\"\n[pose]\nendpoint = \"unix:" << dir
                      << "/robot/pose.sock\"\n[button]\nkind = \"none\"\n[limits]\nmin_tension = 2.0\n"
                      << "max_tension = 300.0\npose_stale_ms = 3000\nsettle_timeout_s = 15.0\n[waypoints]\n"
                      << "min_tension = 2.0\nmax_tension = 300.0\nmargin = 1.5\nz_min = 3.0\nz_max = 18.0\n"
                      << "[equilibrium]\nwindow_s = 1.0\nmax_speed = 0.03\nmax_angular_rate = 0.06\n";
  return path;
}

TEST(InterruptedRun, ADaemonKilledMidRunIsReportedAfterRestartUntilTheNextStart) {
  // GIVEN the virtual small robot and a daemon calibrating it, at waypoint 2 or later
  char pattern[] = "/tmp/cdpr-interrupted-XXXXXX";
  const std::string dir = mkdtemp(pattern);
  ChildProcess robot({built_program("tools/virtual-robot/virtual-robot"), "--preset", "small", "--seed", "1",
                      "--time-scale", "20", "--endpoints", dir + "/robot"},
                     dir + "/robot.log");
  ASSERT_TRUE(wait_until([&] { return std::filesystem::exists(dir + "/robot/ready"); }, 60s)) << robot.log();
  const std::string config = small_robot_config(dir, file_value(dir + "/robot/ready", "modbus_port"));
  const std::string socket = dir + "/control";
  const std::vector<std::string> daemon_argv = {built_program("src/cdpr-calibd"), "--config", config};
  auto first = std::make_unique<ChildProcess>(daemon_argv, dir + "/first.log");
  ASSERT_TRUE(wait_until([&] { return ask(socket, "status")["ok"].boolean(); }, 30s)) << first->log();
  std::this_thread::sleep_for(1s);  // the CANopen nodes' first heartbeats
  ASSERT_TRUE(ask(socket, "start")["ok"].boolean()) << first->log();
  calibctl::JsonValue status;
  ASSERT_TRUE(wait_until(
      [&] {
        status = ask(socket, "status");
        return status["waypoint"].integer() >= 2 || !status["running"].boolean();
      },
      120s))
      << first->log();
  ASSERT_TRUE(status["running"].boolean()) << status["reason"].string() << "\n" << first->log();
  const int waypoint_seen = status["waypoint"].integer();
  const int waypoints = status["waypoints"].integer();

  // WHEN the daemon is killed with SIGKILL and started again
  first->signal(SIGKILL);
  ASSERT_EQ(first->wait_exit(10s), std::optional<int>(128 + SIGKILL));
  EXPECT_TRUE(std::filesystem::exists(dir + "/state/run-in-progress.toml"));
  ChildProcess second(daemon_argv, dir + "/second.log");
  ASSERT_TRUE(wait_until([&] { return ask(socket, "status")["ok"].boolean(); }, 30s)) << second.log();

  // THEN its status and log say the run was interrupted, at which waypoint of how many
  const std::string interrupted = ask(socket, "status")["interrupted"].string();
  std::printf("after restart: %s\n", interrupted.c_str());
  EXPECT_EQ(interrupted.rfind("run interrupted at 20", 0), 0u) << interrupted;
  const std::size_t at = interrupted.find(", waypoint ");
  ASSERT_NE(at, std::string::npos) << interrupted;
  const int waypoint_reported = std::atoi(interrupted.c_str() + at + 11);
  EXPECT_GE(waypoint_reported, waypoint_seen) << interrupted;
  EXPECT_LE(waypoint_reported, waypoint_seen + 1) << interrupted;  // it may have moved on before the kill
  EXPECT_NE(interrupted.find(" of " + std::to_string(waypoints) + " ("), std::string::npos) << interrupted;
  EXPECT_NE(second.log().find("cdpr-calibd: run interrupted at "), std::string::npos) << second.log();
  // AND calibctl status shows it to the operator
  ChildProcess calibctl({built_program("tools/calibctl/calibctl"), "--socket", socket, "status"}, dir + "/calibctl.log");
  EXPECT_EQ(calibctl.wait_exit(30s), std::optional<int>(0));
  EXPECT_NE(calibctl.log().find("\n  interrupted: run interrupted at 20"), std::string::npos) << calibctl.log();

  // AND WHEN a new run starts THEN the report is gone; once it is aborted the marker is removed
  ASSERT_TRUE(ask(socket, "start")["ok"].boolean()) << second.log();
  EXPECT_EQ(ask(socket, "status")["interrupted"].string(), "");
  EXPECT_TRUE(ask(socket, "abort")["ok"].boolean());
  EXPECT_TRUE(wait_until([&] { return !std::filesystem::exists(dir + "/state/run-in-progress.toml"); }, 10s));
  second.signal(SIGTERM);
  EXPECT_EQ(second.wait_exit(30s), std::optional<int>(0)) << second.log();
  robot.signal(SIGTERM);
  robot.wait_exit(30s);
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cdpr::integration
