// A store write that fails mid-run, through the daemon loop on fakes (the
// platform follows the loop's plan, time is the rig's manual clock): the
// first failed write of the run's record (samples.csv, the run marker, its
// history entry) stops the run at the next loop step with the path and the
// errno, the winches halted and the old calibration current; run.toml never
// claims more samples than samples.csv holds; a history that cannot take
// the entry leaves the status naming no entry. The write failures are made
// by a directory in place of the write's temp file (EISDIR, which holds for
// root too); tests/integration/full_disk_test.cc fills a real tmpfs.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../../text_contains.h"
#include "../calibration/calibration_rig.h"
#include "../store/test_broken_directory.h"
#include "daemon_on_fakes.h"
#include "src/formats/run_log_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::daemon {
namespace {

using calibration::CalibrationState;
using ::cdpr::test::contains;

class LoopRig {
 public:
  LoopRig() {
    DaemonConfig config = default_daemon_config();
    config.store = {rig.state_dir.path(), 5};
    config.control_socket = rig.state_dir.path() + "/control";
    config.loop_period_us = calibration::test::kStepUs;
    config.history.model_check = false;
    config.calibrator = calibration::test::rig_options();
    loop = std::make_unique<DaemonLoop>(config, rig.robot,
                                        DaemonDevices{rig.winches, rig.load_cell, rig.pose, &rig.button}, rig.store,
                                        rig.clock, notifier, [this](const std::string& line) { log.push_back(line); });
    rig.active = &loop->machine();  // the platform follows the daemon's waypoints
    EXPECT_TRUE(loop->start().ok());
  }
  // One loop step; the history writes it queued are done before the next
  // (a writer that keeps up, so the step that sees a failure is the next one).
  void tick() {
    rig.clock.advance_us(calibration::test::kStepUs);
    loop->run_once();
    loop->wait_for_history();
  }
  template <class Predicate>
  bool tick_until(Predicate done, int limit = 100'000) {
    for (int k = 0; k < limit; ++k) {
      tick();
      if (done()) return true;
    }
    return false;
  }
  bool ended() const { return !calibration::is_running(status().state) && status().state != CalibrationState::kIdle; }
  const calibration::CalibrationStatus& status() const { return loop->machine().status(); }
  std::string entry(int run) const { return rig.state_dir.path() + "/history/run-00000" + std::to_string(run); }
  std::string log_text() const {
    std::string text;
    for (const std::string& line : log) text += line + "\n";
    return text;
  }

  calibration::test::CalibrationRig rig;
  test::SilentNotifier notifier;
  std::vector<std::string> log;
  std::unique_ptr<DaemonLoop> loop;
};

TEST(StoreWriteFailure, ASamplesWriteThatFailsStopsTheRunAtTheNextStep) {
  // GIVEN a run moving to its second waypoint, whose samples.csv can no longer be replaced
  LoopRig r;
  r.rig.button.press();
  ASSERT_TRUE(r.tick_until([&] { return r.status().samples == 1 && r.status().state == CalibrationState::kMove; }));
  const std::string blocked = r.entry(1) + "/.samples.csv.tmp";
  std::filesystem::create_directory(blocked);
  // WHEN the second sample is logged (and the write of samples.csv that goes with it fails)
  ASSERT_TRUE(r.tick_until([&] { return r.loop->machine().run_log().waypoints.size() == 2; })) << r.status().reason;
  ASSERT_TRUE(calibration::is_running(r.status().state));
  r.tick();
  // THEN the next step fails the run, naming the file and the errno; the winches are halted
  EXPECT_EQ(r.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(contains(r.status().reason, "store: open " + blocked + ": Is a directory: the run's data cannot be kept"))
      << r.status().reason;
  EXPECT_TRUE(contains(r.status().reason, "previous calibration kept")) << r.status().reason;
  EXPECT_GE(r.rig.winches.halts(), 1);
  EXPECT_TRUE(r.rig.winches.all_stopped());
  EXPECT_TRUE(r.rig.previous_calibration_intact());
  EXPECT_EQ(r.status().samples, 2);
  // AND run.toml says what was written: the run failed, with the one sample samples.csv holds
  const auto log = formats::read_run_log_toml(r.entry(1) + "/run.toml");
  ASSERT_TRUE(log) << log.error().message();
  EXPECT_EQ(log->outcome, "failed");
  const auto rows = formats::read_samples_csv(r.entry(1) + "/samples.csv", kCableCount);
  ASSERT_TRUE(rows) << rows.error().message();
  EXPECT_EQ(rows->size(), 1u);
  EXPECT_EQ(log->samples, 1);
  EXPECT_TRUE(contains(r.log_text(), blocked + ": Is a directory")) << r.log_text();
}

TEST(StoreWriteFailure, ARunMarkerWriteThatFailsStopsTheRun) {
  // GIVEN a run at its second waypoint, when the run marker can no longer be replaced
  LoopRig r;
  r.rig.button.press();
  ASSERT_TRUE(r.tick_until([&] { return r.status().waypoint == 2 && r.status().state == CalibrationState::kMove; }));
  const std::string blocked = r.rig.state_dir.path() + "/.run-in-progress.toml.tmp";
  std::filesystem::create_directory(blocked);
  // WHEN the run goes on to its next waypoint (where the marker is rewritten)
  ASSERT_TRUE(r.tick_until([&] { return r.ended() || r.status().waypoint == 3; }));
  // THEN the run fails there, before it moves on, naming the marker and the errno
  EXPECT_EQ(r.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(contains(r.status().reason, "store: run marker: open " + blocked + ": Is a directory"))
      << r.status().reason;
  EXPECT_EQ(r.status().samples, 2);
  EXPECT_TRUE(r.rig.winches.all_stopped());
  EXPECT_TRUE(r.rig.previous_calibration_intact());
}

TEST(StoreWriteFailure, AHistoryThatCannotTakeTheEntryLeavesNoEntryInTheStatus) {
  // GIVEN a history directory that cannot take anything
  LoopRig r;
  store::test::BrokenDirectory broken(r.rig.store.history_dir());
  // WHEN a run is started (and refused in preflight)
  r.rig.button.press();
  ASSERT_TRUE(r.tick_until([&] { return r.ended(); }));
  r.tick();
  // THEN the status does not point at a run directory that is not there
  EXPECT_EQ(r.status().state, CalibrationState::kFailed);
  EXPECT_EQ(r.status().run_outcome, "failed");
  EXPECT_EQ(r.status().run_entry, "") << r.status().run_entry;
}

}  // namespace
}  // namespace cdpr::daemon
