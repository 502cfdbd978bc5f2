#pragma once
// The whole daemon against the virtual robot, in one process over real
// sockets: the virtual robot (tools/virtual-robot) on one thread, the
// daemon's event loop (src/daemon/daemon_loop.h) with the real drivers on
// another, and the test acting as calibctl through the control socket.

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "calibctl/control_client.h"
#include "calibctl/json_value.h"
#include "drivers/can/canopen_winch_bank.h"
#include "drivers/can/listening_winch_bank.h"
#include "drivers/common/load_cell_reader.h"
#include "drivers/modbus/modbus_load_cell.h"
#include "drivers/pose/pose_stream_source.h"
#include "sim/dataset.h"
#include "sim/equilibrium.h"
#include "src/calibration/waypoint_planner.h"
#include "src/daemon/daemon_loop.h"
#include "drivers/modbus/load_cell_presets.h"
#include "robot_time.h"
#include "slowdown.h"
#include "virtual-robot/virtual_robot.h"

namespace cdpr::integration {

class NullNotifier final : public daemon::ServiceNotifier {
 public:
  void ready() override {}
  void status(const std::string&) override {}
  void watchdog() override {}
  void stopping() override {}
};

// The daemon settings of the demo: the endpoints of the virtual robot, whose
// physics runs time_scale times faster, and timeouts that allow for a
// loaded test machine (and for the sanitizer build: slowdown.h); the
// equilibrium thresholds are the shipped ones.
inline daemon::DaemonConfig fast_daemon_config(const std::string& dir, const virtual_robot::VirtualRobot& robot) {
  daemon::DaemonConfig config = daemon::default_daemon_config();
  config.store.state_dir = dir + "/state";
  config.control_socket = dir + "/control";
  config.winches.endpoint = robot.can_endpoint();
  config.load_cell.endpoint = robot.modbus_endpoint();
  // The virtual cell's register map, as an operator would configure it: the
  // vendor's preset and the indicator's decimal point.
  const virtual_robot::LoadCellModel model = robot.options().load_cell.model;
  config.load_cell.preset = virtual_robot::to_string(model);
  config.load_cell.map = *drivers::modbus::load_cell_preset(config.load_cell.preset);
  if (model != virtual_robot::LoadCellModel::kLegacyFloat32) config.load_cell.map.decimals = virtual_robot::kShownDecimals;
  config.load_cell.slave_id = robot.options().load_cell.unit_id;
  config.pose.endpoint = robot.pose_endpoint();
  config.button.gpio = false;
  config.calibrator.settle_timeout_us = slowed_us(15'000'000);
  // The virtual robot answers CAN, Modbus and the pose stream from the thread
  // that also solves its physics, on a machine shared with the other tests:
  // a stall of a few hundred ms is the test machine, not a fault under test
  // (the fault tests with injected clocks cover silent nodes and stale poses).
  config.winches.heartbeat_timeout_us = slowed_us(3'000'000);
  // Simulated time runs faster: a 2 m/s cable pays out 2 x time_scale m per real second.
  config.winches.max_speed_mps = 5.0 * robot.time_scale();
  config.winches.drive.consumer_heartbeat_us = slowed_us(3'000'000);
  config.calibrator.monitor.pose_stale_us = slowed_us(3'000'000);
  config.load_cell.fault_timeout_us = slowed_us(config.load_cell.fault_timeout_us);
  // The nodes are configured over SDO, one frame per node per loop step:
  // a sanitized daemon's slower steps take longer to hear them operational.
  config.calibrator.first_contact_timeout_us = slowed_us(config.calibrator.first_contact_timeout_us);
  // The winches' mechanics, as the operator knows them (drives in rpm need them).
  config.winches.mechanics.drum_diameter_m = robot.options().nodes.drum_diameter_m;
  config.winches.mechanics.gear_ratio = robot.options().nodes.gear_ratio;
  return config;
}

// The small robot (4.4 kg platform, 12.5 m x 4.5 m footprint) needs its own
// limits: the defaults suit the large one, and its reference cable carries
// about 11 N at rest, below the large robot's 20 N minimum.
inline void use_small_robot_limits(daemon::DaemonConfig& config) {
  config.calibrator.monitor.min_tension_n = 2.0;
  config.calibrator.monitor.max_tension_n = 300.0;
  calibration::PlannerOptions& planner = config.calibrator.planner;
  planner.min_tension_n = 2.0;
  planner.max_tension_n = 300.0;
  planner.margin_m = 1.5;
  planner.z_min_m = 3.0;
  planner.z_max_m = 18.0;
}

// The field calibration's acceptance scenario: the large robot, seed 1, nominal anchors
// 0.3 m off the truth, physics 20x faster than real time (slower in the
// sanitizer build: slowdown.h). The test that runs
// it and the one that checks its plan share it, so both see the same robot.
inline virtual_robot::VirtualRobotOptions large_robot_acceptance_options() {
  virtual_robot::VirtualRobotOptions options;
  options.preset = sim::Preset::kLarge;
  options.seed = 1;
  options.time_scale = robot_time_scale(20.0);
  options.anchor_perturbation_m = 0.3;
  return options;
}

// The acceptance robot's true and nominal data and the daemon's plan for it
// (default planner settings but the selection), made as the daemon makes it
// at the start position: offsets estimated there, waypoints planned from
// the nominal anchors. Failures are test failures (check plan.ok()).
struct PlannedAcceptanceRobot {
  sim::SimulatedDataset data;
  Eigen::Vector3d start_world = Eigen::Vector3d::Zero();
  calibration::WaypointPlan plan;
};

inline std::optional<PlannedAcceptanceRobot> plan_acceptance_robot(calibration::WaypointSelection selection) {
  const virtual_robot::VirtualRobotOptions robot_options = large_robot_acceptance_options();
  auto data = sim::simulate_dataset(virtual_robot::dataset_config(robot_options));
  if (!data) {
    ADD_FAILURE() << data.error();
    return std::nullopt;
  }
  const sim::TrueRobot& truth = data->true_robot;
  const Eigen::Vector3d start_world = virtual_robot::start_position_world(robot_options.preset);
  const auto start = sim::solve_equilibrium(truth, start_world, 0.0);
  if (!start) {
    ADD_FAILURE() << start.error().message;
    return std::nullopt;
  }
  std::array<double, kCableCount> encoder_m{};
  for (int i = 0; i < kCableCount; ++i) encoder_m[i] = start->cables[i].payout_m + truth.encoder_offset_m[i];
  const auto offsets = calibration::estimate_payout_offsets(data->nominal, start_world, encoder_m);
  if (!offsets) {
    ADD_FAILURE() << offsets.error();
    return std::nullopt;
  }
  calibration::PlannerOptions options = daemon::default_daemon_config().calibrator.planner;
  options.selection = selection;
  calibration::WaypointPlan plan = calibration::plan_waypoints(data->nominal, *offsets, start_world, options);
  return PlannedAcceptanceRobot{std::move(*data), start_world, std::move(plan)};
}

// One request through a fresh client of the daemon at `socket`, parsed; a
// failed request is a test failure. The wait is generous (calibctl's default
// is 10 s): at a load average near 10 the daemon's loop thread was once
// starved past 10 s, and the daemon's responsiveness under load is
// control_socket_test's job.
inline calibctl::JsonValue ask_daemon(const std::string& socket, const std::string& request) {
  constexpr int kResponseTimeoutMs = 60'000;
  calibctl::ControlClient client;
  std::string error, response;
  EXPECT_TRUE(client.connect(socket, error)) << error;
  EXPECT_TRUE(client.request(request, response, error, kResponseTimeoutMs)) << error;
  auto value = calibctl::JsonValue::parse(response);
  EXPECT_TRUE(value.has_value()) << response;
  return value ? *value : calibctl::JsonValue{};
}

class VirtualRobotRig {
 public:
  // `before_start` runs once the robot is up, the configuration made and the
  // store open, before the drivers and the daemon are built from them (to
  // change the configuration, commit a previous calibration or set daemon_log).
  explicit VirtualRobotRig(virtual_robot::VirtualRobotOptions options,
                           const std::function<void(VirtualRobotRig&)>& before_start = {}) {
    char pattern[] = "/tmp/cdpr-integration-XXXXXX";
    dir = mkdtemp(pattern);
    options.dir = dir + "/robot";
    std::filesystem::create_directories(options.dir);
    auto created = virtual_robot::VirtualRobot::create(options);
    if (!created) ADD_FAILURE() << created.error();
    robot = std::move(*created);
    robot_thread = std::thread([this] { robot->run(stop_robot); });

    config = fast_daemon_config(dir, *robot);
    if (options.preset == sim::Preset::kSmall) use_small_robot_limits(config);
    store = std::make_unique<store::CalibrationStore>(config.store);
    EXPECT_TRUE(store->open());
    if (before_start) before_start(*this);
    // As main() does: in watch mode the listen-only bank, which cannot send.
    if (config.operation.watch) {
      winches = std::make_unique<drivers::can::ListeningWinchBank>(
          config.winches, config.operation.listen, drivers::can::make_can_connector(config.winches.endpoint));
    } else {
      winches = std::make_unique<drivers::can::CanopenWinchBank>(
          config.winches, drivers::can::make_can_connector(config.winches.endpoint));
    }
    // The daemon runs on the robot's clock, as cdpr-calibd --sim-clock does:
    // a robot thread starved of CPU is a slower robot, not a device fault.
    const hal::Clock& clock = robot->clock();
    load_cell = std::make_unique<drivers::modbus::ModbusLoadCell>(config.load_cell, clock);
    load_cell_reader = std::make_unique<drivers::LoadCellReader>(
        *load_cell, clock,
        drivers::LoadCellReaderOptions{config.load_cell.poll_interval_us, config.load_cell.fault_timeout_us,
                                       daemon::DaemonLoop::kReconnectIntervalUs});
    pose = std::make_unique<drivers::pose::PoseStreamSource>(config.pose.endpoint, clock);
    loop = std::make_unique<daemon::DaemonLoop>(config, robot->nominal_robot(),
                                                daemon::DaemonDevices{*winches, *load_cell_reader, *pose, nullptr}, *store,
                                                clock, notifier, daemon_log);
    const hal::Status started = loop->start();
    EXPECT_TRUE(started.ok()) << started.to_string();
    loop_thread = std::thread([this] { loop->run(stop_loop); });
  }

  ~VirtualRobotRig() {
    stop_daemon();
    stop_robot.store(true);
    robot_thread.join();
    if (::testing::Test::HasFailure() && robot) {
      // What tells a starved robot or a slack cable's solve from a daemon fault.
      std::printf("virtual robot: %d equilibrium solves failed, %d with a slack cable; %.1f s of robot time not "
                  "simulated while starved of CPU\n",
                  robot->physics().failed_solves(), robot->physics().slack_solves(), robot->robot_time_lost_s());
    }
    if (!keep_dir) std::filesystem::remove_all(dir);
  }

  void stop_daemon() {
    if (!loop_thread.joinable()) return;
    stop_loop.store(true);
    loop_thread.join();
  }

  calibctl::JsonValue ask(const std::string& request) { return ask_daemon(config.control_socket, request); }

  std::string dir;
  bool keep_dir = false;
  std::unique_ptr<virtual_robot::VirtualRobot> robot;
  std::atomic<bool> stop_robot{false};
  std::thread robot_thread;
  daemon::DaemonConfig config;
  std::unique_ptr<hal::WinchBank> winches;  // CANopen master, or the listener in watch mode
  std::function<void(const std::string&)> daemon_log;  // the daemon's log lines (none: not shown)
  std::unique_ptr<drivers::modbus::ModbusLoadCell> load_cell;
  std::unique_ptr<drivers::LoadCellReader> load_cell_reader;  // what the daemon reads, as in main()
  std::unique_ptr<drivers::pose::PoseStreamSource> pose;
  std::unique_ptr<store::CalibrationStore> store;
  NullNotifier notifier;
  std::unique_ptr<daemon::DaemonLoop> loop;
  std::atomic<bool> stop_loop{false};
  std::thread loop_thread;
};

}  // namespace cdpr::integration
