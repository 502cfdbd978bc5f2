#pragma once
// The daemon in watch mode ([operation] watch = true) against the virtual
// robot in operation (its own controller moves the platform), in one
// process over real sockets, as main() wires it: the listen-only winch
// bank instead of the CANopen master.

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "drivers/can/listening_winch_bank.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {

// The truth as a committed calibration (sigmas 1 mm): what a good run left.
inline Calibration truth_calibration(const virtual_robot::VirtualRobot& robot) {
  Calibration c;
  c.created = "2026-12-07T07:00:00Z";
  c.robot = robot.nominal_robot().name;
  c.samples = 30;
  for (const WinchTruth& w : robot.truth().winches) {
    WinchCalibration winch;
    winch.anchor_world = w.anchor_world;
    winch.anchor_sigma = Eigen::Vector3d::Constant(1e-3);
    winch.offset_m = w.offset_m;
    winch.offset_sigma_m = 1e-3;
    c.winches.push_back(winch);
  }
  return c;
}

// The virtual robot in operation: the large robot, rests of 40-50 s of
// simulated time. Its platform sways with a period of about 18 s (the
// physics' from the cable geometry) at damping ratio 0.6: 25-30 s after a
// stop it is within the pose noise of its rest, and the daemon sees a rest
// once its window mean has held still (src/operation/rest_watch.h).
inline virtual_robot::VirtualRobotOptions operating_robot_options(std::uint64_t seed) {
  virtual_robot::VirtualRobotOptions options;
  options.preset = sim::Preset::kLarge;
  options.seed = seed;
  options.time_scale = robot_time_scale(10.0);
  options.anchor_perturbation_m = 0.3;
  options.physics.damping_ratio = 0.6;
  options.operation.enabled = true;
  options.operation.rest_min_s = 40.0;
  options.operation.rest_max_s = 50.0;
  return options;
}

class WatchRig {
 public:
  WatchRig(virtual_robot::VirtualRobotOptions options, bool commit_truth = true) {
    char pattern[] = "/tmp/cdpr-watch-XXXXXX";
    dir = mkdtemp(pattern);
    options.dir = dir + "/robot";
    std::filesystem::create_directories(options.dir);
    auto created = virtual_robot::VirtualRobot::create(options);
    if (!created) ADD_FAILURE() << created.error();
    robot = std::move(*created);
    robot_thread = std::thread([this] { robot->run(stop_robot); });

    config = fast_daemon_config(dir, *robot);
    config.operation.watch = true;
    // Its 100 Hz pose stream is 10 poses per second of its own (simulated)
    // time at x10: the rest window of 2 s holds 20 of them.
    config.calibrator.equilibrium.min_samples = 20;
    config.operation.pose_output = "unix:" + dir + "/pose-out.sock";
    config.winches.encoder.measuring_range = robot->options().nodes.encoder_range_counts;
    store = std::make_unique<store::CalibrationStore>(config.store);
    EXPECT_TRUE(store->open());
    if (commit_truth) {
      EXPECT_TRUE(store->commit(truth_calibration(*robot)));
    }
    const hal::Clock& clock = robot->clock();
    winches = std::make_unique<drivers::can::ListeningWinchBank>(
        config.winches, config.operation.listen, drivers::can::make_can_connector(config.winches.endpoint));
    load_cell = std::make_unique<drivers::modbus::ModbusLoadCell>(config.load_cell, clock);
    load_cell_reader = std::make_unique<drivers::LoadCellReader>(
        *load_cell, clock,
        drivers::LoadCellReaderOptions{config.load_cell.poll_interval_us, config.load_cell.fault_timeout_us,
                                       daemon::DaemonLoop::kReconnectIntervalUs});
    pose = std::make_unique<drivers::pose::PoseStreamSource>(config.pose.endpoint, clock);
    loop = std::make_unique<daemon::DaemonLoop>(config, robot->nominal_robot(),
                                                daemon::DaemonDevices{*winches, *load_cell_reader, *pose, nullptr},
                                                *store, clock, notifier, [this](const std::string& line) {
                                                  std::printf("cdpr-calibd: %s\n", line.c_str());
                                                  std::fflush(stdout);
                                                });
    const hal::Status started = loop->start();
    EXPECT_TRUE(started.ok()) << started.to_string();
    loop_thread = std::thread([this] { loop->run(stop_loop); });
  }

  ~WatchRig() {
    stop_daemon();
    stop_robot.store(true);
    robot_thread.join();
    std::filesystem::remove_all(dir);
  }

  void stop_daemon() {
    if (!loop_thread.joinable()) return;
    stop_loop.store(true);
    loop_thread.join();
  }

  calibctl::JsonValue ask(const std::string& request) { return ask_daemon(config.control_socket, request); }

  std::string dir;
  std::unique_ptr<virtual_robot::VirtualRobot> robot;
  std::atomic<bool> stop_robot{false};
  std::thread robot_thread;
  daemon::DaemonConfig config;
  std::unique_ptr<store::CalibrationStore> store;
  std::unique_ptr<drivers::can::ListeningWinchBank> winches;
  std::unique_ptr<drivers::modbus::ModbusLoadCell> load_cell;
  std::unique_ptr<drivers::LoadCellReader> load_cell_reader;
  std::unique_ptr<drivers::pose::PoseStreamSource> pose;
  NullNotifier notifier;
  std::unique_ptr<daemon::DaemonLoop> loop;
  std::atomic<bool> stop_loop{false};
  std::thread loop_thread;
};

}  // namespace cdpr::integration
