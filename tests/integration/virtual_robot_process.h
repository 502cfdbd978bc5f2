#pragma once
// The virtual robot as its own process and a cdpr-calibd configuration for
// it, for the tests that run real daemon processes (kill -9, a read-only
// store in a mount namespace, a hidden effect). The physics runs 20x faster
// than real time (slower in the sanitizer build, the daemon's timeouts
// stretched alike: slowdown.h); the daemon keeps its shipped equilibrium
// thresholds and, for the small robot, gets its limits (the reference cable
// may dip below the planner's 2 N while the small platform swings between
// waypoints).

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "calibctl/control_client.h"
#include "calibctl/json_value.h"
#include "daemon_process.h"
#include "drivers/clock/shared_clock.h"
#include "robot_time.h"
#include "slowdown.h"

namespace cdpr::integration {

class VirtualRobotProcess {
 public:
  // `preset`: "small" or "large"; `waypoint_count` of the plan;
  // `extra_tables`: more TOML tables appended to the daemon's configuration
  // (not [store] .. [waypoints]); `robot_options`: more virtual-robot
  // options (not --preset, --seed, --time-scale, --endpoints).
  explicit VirtualRobotProcess(const std::string& preset = "small", int waypoint_count = 35,
                               const std::string& extra_tables = "",
                               const std::vector<std::string>& robot_options = {}) {
    using namespace std::chrono_literals;
    char pattern[] = "/tmp/cdpr-robot-process-XXXXXX";
    dir = mkdtemp(pattern);
    socket = dir + "/control";
    state_dir = dir + "/state";
    std::vector<std::string> robot_argv{built_program("tools/virtual-robot/virtual-robot"), "--preset", preset,
                                        "--seed", "1", "--time-scale", std::to_string(robot_time_scale(20.0)),
                                        "--endpoints", dir + "/robot"};
    robot_argv.insert(robot_argv.end(), robot_options.begin(), robot_options.end());
    robot_ = std::make_unique<ChildProcess>(robot_argv, dir + "/robot.log");
    if (!wait_until([&] { return std::filesystem::exists(dir + "/robot/ready"); }, slowed(60s))) {
      ADD_FAILURE() << "the virtual robot did not start: " << robot_->log();
    }
    hal::Status opened;
    robot_clock_ = drivers::SharedClock::open(dir + "/robot/clock", opened);
    if (!robot_clock_) {
      ADD_FAILURE() << "the virtual robot's clock: " << opened.to_string();
      robot_clock_ = drivers::SharedClock::in_memory(0);  // still a clock: waits on it end at once
    }
    config = dir + "/cdpr-calibd.toml";
    const bool small = preset == "small";
    // The timeouts stretched for a loaded test machine are beyond what a
    // robot should run with: acknowledged (docs/configuration.md, unsafe_ok).
    std::ofstream(config) << "robot = \"" << dir << "/robot/robot.toml\"\n" << kLoadedMachineUnsafeOk
                          << "[store]\nstate_dir = \"" << state_dir
                          << "\"\n[control]\nsocket = \"" << socket << "\"\n[winches]\nendpoint = \"unix:" << dir
                          << "/robot/can.sock\"\nheartbeat_timeout_ms = " << 3000 * slowdown()
                          << "\n[winches.drive]\nconsumer_heartbeat_ms = " << 500 * slowdown()
                          << "\n[load_cell]\nendpoint = "
                          << "\"tcp:127.0.0.1:" << ready_value("modbus_port")
                          << "\"\nfault_timeout_ms = " << 1000 * slowdown() << "\n[pose]\nendpoint = \"unix:"
                          << dir << "/robot/pose.sock\"\n[button]\nkind = \"none\"\n[limits]\n"
                          << (small ? "min_tension = 0.5\nmax_tension = 300.0\n" : "")
                          << "pose_stale_ms = " << 3000 * slowdown() << "\nsettle_timeout_s = " << 15 * slowdown()
                          << ".0\n[waypoints]\n"
                          << (small ? "min_tension = 2.0\nmax_tension = 300.0\nmargin = 1.5\nz_min = 3.0\n"
                                      "z_max = 18.0\n"
                                    : "")
                          << "count = " << waypoint_count << "\n" << extra_tables;
  }
  ~VirtualRobotProcess() {
    robot_->signal(SIGTERM);
    robot_->signal(SIGCONT);  // a test that ended with the robot starved
    robot_->wait_exit(slowed(std::chrono::seconds(30)));
    if (!::testing::Test::HasFailure()) {
      std::filesystem::remove_all(dir);
      return;
    }
    // Its exit line tells a starved robot (robot time lost) or a slack
    // cable's solve from a fault of the daemon's.
    std::printf("kept %s; the virtual robot's log:\n%s", dir.c_str(), robot_->log().c_str());
  }

  // cdpr-calibd on this configuration, behind `prefix` (e.g. unshare ... --), logging to <dir>/<name>.log.
  std::unique_ptr<ChildProcess> start_daemon(const std::string& name, std::vector<std::string> prefix = {}) const {
    // On the robot's clock: a robot process starved of CPU is a slower robot, not a fault.
    prefix.insert(prefix.end(),
                  {built_program("src/cdpr-calibd"), "--config", config, "--sim-clock", dir + "/robot/clock"});
    return std::make_unique<ChildProcess>(prefix, dir + "/" + name + ".log");
  }

  // One request on a fresh connection; a null value when there is no answer.
  calibctl::JsonValue ask(const std::string& request) const {
    calibctl::ControlClient client;
    std::string error, response;
    if (!client.connect(socket, error) || !client.request(request, response, error, 30'000 * slowdown())) return {};
    auto value = calibctl::JsonValue::parse(response);
    return value ? *value : calibctl::JsonValue{};
  }
  bool answers() const { return ask("status")["ok"].boolean(); }
  // The virtual robot stops being scheduled (SIGSTOP) or runs again
  // (SIGCONT): a robot starved of CPU, whose clock stands still meanwhile.
  void starve_robot(bool starved) { robot_->signal(starved ? SIGSTOP : SIGCONT); }
  // While it lives, the virtual robot gets 2 ms of every 20 ms of the wall
  // clock, as on a machine whose cores are taken by others: its clock runs
  // at a tenth of its speed or less.
  class StarvedRobot {
   public:
    explicit StarvedRobot(VirtualRobotProcess& rig) : rig_(rig), thread_([this] { starve(); }) {}
    ~StarvedRobot() {
      done_ = true;
      thread_.join();
      rig_.starve_robot(false);
    }
    StarvedRobot(const StarvedRobot&) = delete;
    StarvedRobot& operator=(const StarvedRobot&) = delete;

   private:
    void starve() {
      using namespace std::chrono_literals;
      while (!done_) {
        rig_.starve_robot(true);
        std::this_thread::sleep_for(18ms);
        rig_.starve_robot(false);
        std::this_thread::sleep_for(2ms);
      }
    }
    VirtualRobotProcess& rig_;
    std::atomic<bool> done_{false};
    std::thread thread_;
  };
  // The virtual robot's clock (its <endpoints>/clock), which the daemons run on.
  const hal::Clock& robot_clock() const { return *robot_clock_; }
  // wait_until() in the robot's time (robot_time.h).
  template <class Predicate>
  bool wait_until_robot(Predicate ready, std::chrono::milliseconds timeout) const {
    return integration::wait_until_robot(*robot_clock_, ready, timeout);
  }
  // The status once the run has ended (or the last one seen after `timeout` of the robot's time).
  calibctl::JsonValue wait_for_end(std::chrono::seconds timeout) const {
    calibctl::JsonValue status;
    wait_until_robot(
        [&] {
          status = ask("status");
          return status["ok"].boolean() && !status["running"].boolean();
        },
        timeout);
    return status;
  }

  std::string dir, socket, state_dir, config;

 private:
  std::string ready_value(const std::string& key) const {
    std::ifstream file(dir + "/robot/ready");
    std::string line;
    while (std::getline(file, line)) {
      if (line.rfind(key + " = ", 0) == 0) return line.substr(key.size() + 3);
    }
    return {};
  }

  std::unique_ptr<ChildProcess> robot_;
  std::unique_ptr<drivers::SharedClock> robot_clock_;
};

}  // namespace cdpr::integration
