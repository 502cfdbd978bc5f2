#pragma once
// A robot of behavioural fakes for the state machine's component tests: the
// large robot's winches, load cell, pose source and button, an injected
// clock, a store holding a previous calibration, and a platform "physics"
// that swings while the winches move and rests at the planned waypoint pose
// once they stop. The solve step is injected, so these tests check the
// state machine, not the solver's accuracy.

#include <cmath>
#include <memory>
#include <string>

#include "../../fakes/fake_button.h"
#include "../../fakes/fake_load_cell.h"
#include "../../fakes/fake_pose_source.h"
#include "../../fakes/fake_winch_bank.h"
#include "../../fakes/manual_clock.h"
#include "../../solver/model/test_robots.h"
#include "../store/store_test_support.h"
#include "src/calibration/calibration_state_machine.h"

namespace cdpr::calibration::test {

constexpr hal::TimeUs kStepUs = 20'000;  // daemon loop period

inline fakes::FakeWinchBank::Options fast_winches() {
  fakes::FakeWinchBank::Options options;
  options.speed_m_per_s = 20.0;
  return options;
}

inline CalibratorOptions rig_options() {
  CalibratorOptions options;
  options.planner.waypoint_count = 6;
  options.planner.grid_xy = 3;
  options.planner.grid_z = 2;
  options.planner.margin_m = 20.0;
  options.planner.z_min_m = 5.0;
  options.planner.z_max_m = 35.0;
  options.equilibrium.window_us = 1'000'000;
  options.equilibrium.min_samples = 20;
  // The fake platform does not sway: the shortest return window (twice the
  // rest window) keeps a waypoint's settle at two seconds.
  options.equilibrium.sway_window_us = 2'000'000;
  options.equilibrium_capacity = 200;
  options.validation.min_samples = 4;
  options.settle_timeout_us = 10'000'000;
  options.move_timeout_us = 60'000'000;
  return options;
}

// The stored calibration before the run: nominal anchors, offsets 2 m.
inline Calibration previous_calibration(const Robot& robot) {
  Calibration calibration = store::test::calibration_version(1);
  for (int i = 0; i < kCableCount; ++i) {
    calibration.winches[i].anchor_world = robot.winches[i].anchor_world;
    calibration.winches[i].offset_m = 2.0;
  }
  return calibration;
}

// A fit at the noise level, anchors 3 cm from the previous ones.
inline CalibrationResult good_fit(const Robot& robot, const std::vector<Sample>& samples) {
  CalibrationResult result;
  result.ok = true;
  result.calibration = previous_calibration(robot);
  for (WinchCalibration& winch : result.calibration.winches) winch.anchor_world.x() += 0.03;
  result.calibration.samples = static_cast<int>(samples.size());
  result.calibration.fit.rms_encoder_m = robot.noise.encoder_m;
  result.calibration.fit.rms_force_n = robot.noise.force_n;
  return result;
}

class CalibrationRig {
 public:
  // Without `stored_calibration` the store is empty: a robot's first run.
  explicit CalibrationRig(CalibratorOptions options = rig_options(), bool stored_calibration = true)
      : winches(fast_winches()), load_cell(clock), pose(clock), store({state_dir.path(), 5}) {
    EXPECT_TRUE(store.open());
    if (stored_calibration) {
      EXPECT_TRUE(store.commit(previous_calibration(robot)));
      previous_bytes = store::test::file_bytes(store.current_path());
    }
    EXPECT_TRUE(winches.open().ok());
    EXPECT_TRUE(load_cell.open().ok());
    EXPECT_TRUE(pose.open().ok());
    load_cell.set_tension(300.0, true);
    pose.set_generator([this](hal::TimeUs now_us) { return platform(now_us); });
    solve = [this](const Robot& r, const std::vector<Sample>& samples) {
      ++solves;
      return good_fit(r, samples);
    };
    machine = std::make_unique<CalibrationStateMachine>(
        robot, CalibratorDevices{winches, load_cell, pose, &button, store}, options,
        [this](const Robot& r, const std::vector<Sample>& samples) { return solve(r, samples); },
        [] { return std::string("2026-11-23T08:00:00Z"); });
    active = machine.get();
  }

  // Steps the daemon loop until `done()` or `limit_us` of injected time.
  template <class Predicate>
  bool run_until(Predicate done, hal::TimeUs limit_us = 600'000'000) {
    const hal::TimeUs end_us = clock.now_us() + limit_us;
    while (clock.now_us() < end_us) {
      clock.advance_us(kStepUs);
      machine->step(clock.now_us());
      if (done()) return true;
    }
    return false;
  }
  bool run_to_end() {
    return run_until([this] { return !is_running(status().state) && status().state != CalibrationState::kIdle; });
  }
  bool run_to(CalibrationState state, int waypoint = 0) {
    return run_until([=, this] {
      return status().state == state && (waypoint == 0 || status().waypoint == waypoint);
    });
  }

  // Runs until the winches are travelling to waypoint k (faults injected
  // there show whether the machine really stops them).
  bool run_to_moving(int waypoint) {
    return run_to(CalibrationState::kMove, waypoint) && run_until([this] {
             for (int i = 0; i < winches.winch_count(); ++i) {
               if (winches.moving(i)) return true;
             }
             return false;
           });
  }

  const CalibrationStatus& status() const { return machine->status(); }
  std::string current_bytes() const { return store::test::file_bytes(store.current_path()); }
  bool previous_calibration_intact() const { return current_bytes() == previous_bytes; }

  // The platform: swings while any winch moves, rests at the current
  // waypoint's planned pose otherwise (or at the start before a plan).
  hal::PoseSample platform(hal::TimeUs now_us) {
    Eigen::Vector3d position(120.0, 110.0, 10.0);
    Eigen::Quaterniond world_R_platform = Eigen::Quaterniond::Identity();
    if (const Waypoint* waypoint = current_waypoint()) {
      position = waypoint->rest.world_T_platform.position_world;
      world_R_platform = waypoint->rest.world_T_platform.world_R_platform;
    }
    bool moving = false;
    for (int i = 0; i < winches.winch_count(); ++i) moving = moving || winches.moving(i);
    if (moving || swinging) position.x() += 0.2 * std::sin(1e-6 * static_cast<double>(now_us));
    hal::PoseSample sample;
    sample.platform_world = {position.x(), position.y(), position.z()};
    sample.world_R_platform = {world_R_platform.w(), world_R_platform.x(), world_R_platform.y(),
                               world_R_platform.z()};
    sample.valid = true;
    sample.source_time_us = now_us;
    return sample;
  }

  const Waypoint* current_waypoint() const { return active->current_waypoint(); }

  // The load cell reads the modelled tension of the reference cable at the
  // current waypoint, so samples are consistent with the catenary model.
  void use_model_tension() {
    load_cell.set_source([this](hal::TimeUs) {
      const Waypoint* waypoint = current_waypoint();
      return std::make_pair(waypoint ? waypoint->rest.tension_n[robot.reference_cable] : 300.0, true);
    });
  }

  fakes::ManualClock clock;
  fakes::FakeWinchBank winches;
  fakes::FakeLoadCell load_cell;
  fakes::FakePoseSource pose;
  fakes::FakeButton button;
  store::test::TempStateDir state_dir;
  store::CalibrationStore store;
  Robot robot = cdpr::test::large_robot();
  std::string previous_bytes;
  SolveFunction solve;
  int solves = 0;
  bool swinging = false;  // the platform never comes to rest
  std::unique_ptr<CalibrationStateMachine> machine;
  const CalibrationStateMachine* active = nullptr;  // whose plan the platform follows
};

}  // namespace cdpr::calibration::test
