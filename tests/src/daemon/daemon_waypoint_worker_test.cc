// The daemon loop runs the sequential strategy's re-solve on a worker: while
// a slow re-solve runs, the loop keeps stepping, so the winch bank's update
// (where the CANopen master's heartbeat goes out) runs every period and the
// drives, watching that heartbeat, do not quick-stop; a fault meanwhile ends
// the run, no new run starts before the worker is done, and its late
// result is dropped. Time is the rig's manual clock; the slow re-solve
// waits for the test's release instead of taking wall-clock time.

#include <atomic>
#include <future>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../../text_contains.h"
#include "../calibration/calibration_rig.h"
#include "daemon_on_fakes.h"

namespace cdpr::daemon {
namespace {

// A re-solve that is slow. On a worker it waits for release(); on the loop
// thread (where it must not run) it takes its time on the loop's clock.
class SlowResolve {
 public:
  explicit SlowResolve(fakes::ManualClock& clock) : clock_(clock), released_(release_.get_future().share()) {}

  CalibrationResult operator()(const Robot& robot, const std::vector<Sample>& samples,
                               const CalibrationOptions& options) {
    if (std::this_thread::get_id() == loop_thread_) {
      ++on_loop_thread_;
      clock_.advance_us(2'000'000);
    } else {
      entered_ = true;
      released_.wait();
    }
    return calibrate(robot, samples, options);
  }
  void release() { release_.set_value(); }
  bool entered() const { return entered_; }
  int on_loop_thread() const { return on_loop_thread_; }

 private:
  fakes::ManualClock& clock_;
  const std::thread::id loop_thread_ = std::this_thread::get_id();
  std::atomic<bool> entered_{false};
  std::atomic<int> on_loop_thread_{0};
  std::promise<void> release_;
  std::shared_future<void> released_;
};

struct Daemon {
  Daemon() {
    rig.winches = fakes::FakeWinchBank(watched_winches());
    rig.use_model_tension();
    DaemonConfig config = default_daemon_config();
    config.store = {rig.state_dir.path(), 5};
    config.control_socket = rig.state_dir.path() + "/control";
    config.loop_period_us = calibration::test::kStepUs;
    config.history.model_check = false;
    config.calibrator = calibration::test::rig_options();
    config.calibrator.planner.grid_xy = 4;
    config.calibrator.strategy = calibration::WaypointStrategy::kSequential;
    config.calibrator.sequential.max_count = 8;
    config.calibrator.sequential.resolve = [this](const Robot& robot, const std::vector<Sample>& samples,
                                                  const CalibrationOptions& options) {
      return slow(robot, samples, options);
    };
    loop = std::make_unique<DaemonLoop>(config, rig.robot,
                                        DaemonDevices{rig.winches, rig.load_cell, rig.pose, &rig.button}, rig.store,
                                        rig.clock, notifier, nullptr);
    rig.active = &loop->machine();  // the platform follows the daemon's waypoints
  }
  ~Daemon() {
    if (!released) slow.release();
  }
  // The drives quick-stop after 500 ms without the master's heartbeat (the
  // shipped consumer_heartbeat_ms).
  static fakes::FakeWinchBank::Options watched_winches() {
    fakes::FakeWinchBank::Options options = calibration::test::fast_winches();
    options.consumer_heartbeat_us = 500'000;
    return options;
  }
  void tick() {
    rig.clock.advance_us(calibration::test::kStepUs);
    loop->run_once();
  }
  const calibration::CalibrationStatus& status() const { return loop->machine().status(); }

  calibration::test::CalibrationRig rig;
  SlowResolve slow{rig.clock};
  bool released = false;
  test::SilentNotifier notifier;
  std::unique_ptr<DaemonLoop> loop;
};

TEST(DaemonWaypointWorker, TheLoopKeepsTheDrivesHeartbeatAndMonitorGoingDuringASlowReSolve) {
  // GIVEN the daemon on the sequential strategy, drives watching its
  // heartbeat, and a re-solve that takes until the test releases it
  Daemon daemon;
  ASSERT_TRUE(daemon.loop->start().ok());
  daemon.rig.button.press();
  // WHEN the run reaches its first re-solve
  for (int k = 0; k < 1'000'000 && !daemon.slow.entered(); ++k) {
    if (k > 10 && !calibration::is_running(daemon.status().state)) break;
    daemon.tick();
    std::this_thread::yield();
  }
  EXPECT_EQ(daemon.rig.winches.heartbeat_losses(), 0);
  ASSERT_EQ(daemon.slow.on_loop_thread(), 0) << "the re-solve ran on the loop thread";
  ASSERT_TRUE(daemon.slow.entered()) << daemon.status().reason;
  // THEN for 1 s of loop ticks the drives are updated every tick and keep going
  const int updates = daemon.rig.winches.updates();
  for (int k = 0; k < 50; ++k) daemon.tick();
  EXPECT_EQ(daemon.rig.winches.updates(), updates + 50);
  EXPECT_EQ(daemon.rig.winches.heartbeat_losses(), 0);
  EXPECT_EQ(daemon.status().state, calibration::CalibrationState::kSample) << daemon.status().reason;
  EXPECT_EQ(daemon.status().detail, "choosing the next waypoint");
  // AND a node falling silent meanwhile ends the run with a quick stop
  daemon.rig.winches.silence(1);
  for (int k = 0; k < 100 && calibration::is_running(daemon.status().state); ++k) daemon.tick();
  EXPECT_EQ(daemon.status().state, calibration::CalibrationState::kFailed);
  EXPECT_TRUE(cdpr::test::contains(daemon.status().reason, "winch 1")) << daemon.status().reason;
  EXPECT_GE(daemon.rig.winches.quick_stops(), 1);
  // AND a start while the worker still runs is refused
  daemon.rig.winches.silence(1, false);
  daemon.rig.button.press();
  daemon.tick();
  EXPECT_EQ(daemon.status().state, calibration::CalibrationState::kFailed);
  EXPECT_TRUE(cdpr::test::contains(daemon.status().note, "still finishing")) << daemon.status().note;
  // AND once the worker is done its result is dropped and a start is accepted
  daemon.slow.release();
  daemon.released = true;
  for (int k = 0; k < 1'000'000 && daemon.loop->machine().waypoint_job_out(); ++k) {
    daemon.tick();
    std::this_thread::yield();
  }
  EXPECT_FALSE(daemon.loop->machine().waypoint_job_out());
  EXPECT_EQ(daemon.status().state, calibration::CalibrationState::kFailed);
  daemon.rig.button.press();
  daemon.tick();
  EXPECT_TRUE(calibration::is_running(daemon.status().state)) << daemon.status().note;
}

}  // namespace
}  // namespace cdpr::daemon
