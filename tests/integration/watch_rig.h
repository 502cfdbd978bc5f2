#pragma once
// The daemon in watch mode ([operation] watch = true) against the virtual
// robot in operation (its own controller moves the platform): the
// VirtualRobotRig's start-up with the listen-only winch bank instead of the
// CANopen master, as main() wires it.

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

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

// The rig in watch mode: the listen-only winch bank, the pose output, the
// log lines printed, and (commit_truth) the truth committed beforehand.
class WatchRig : public VirtualRobotRig {
 public:
  explicit WatchRig(virtual_robot::VirtualRobotOptions options, bool commit_truth = true)
      : VirtualRobotRig(std::move(options), [commit_truth](VirtualRobotRig& rig) { watch(rig, commit_truth); }) {}

 private:
  static void watch(VirtualRobotRig& rig, bool commit_truth) {
    rig.config.operation.watch = true;
    // Its 100 Hz pose stream is 10 poses per second of its own (simulated)
    // time at x10: the rest window of 2 s holds 20 of them.
    rig.config.calibrator.equilibrium.min_samples = 20;
    rig.config.operation.pose_output = "unix:" + rig.dir + "/pose-out.sock";
    rig.config.winches.encoder.measuring_range = rig.robot->options().nodes.encoder_range_counts;
    if (commit_truth) {
      EXPECT_TRUE(rig.store->commit(truth_calibration(*rig.robot)));
    }
    rig.daemon_log = [](const std::string& line) {
      std::printf("cdpr-calibd: %s\n", line.c_str());
      std::fflush(stdout);
    };
  }
};

}  // namespace cdpr::integration
