// Every run's data kept (state machine against fakes, recorder as the
// daemon loop drives it): committed, aborted and interrupted runs keep
// their samples, robot.toml and log; the disk budget prunes the oldest but
// never the current calibration's run; an entry that cannot be written stops
// the run and is logged.

#include "src/daemon/run_recorder.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "../calibration/calibration_rig.h"
#include "src/control/control_dispatch.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"
#include "src/store/atomic_file.h"
#include "../../text_contains.h"

namespace cdpr::daemon {
namespace {

using calibration::CalibrationState;
using calibration::test::CalibrationRig;

using ::cdpr::test::contains;

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

class RecordedRig {
 public:
  explicit RecordedRig(std::uintmax_t budget_bytes = 1'000'000'000,
                       std::optional<DiagnosisOptions> model_check = std::nullopt,
                       std::optional<CalibrationOptions> report_fit = std::nullopt)
      : recorder(std::make_unique<RunRecorder>(rig.store.state_dir(), budget_bytes, std::move(model_check),
                                               report_fit)) {
    for (std::string& message : recorder->recover("2026-11-23T08:00:00Z", "died")) messages.push_back(message);
  }
  bool run_until(const std::function<bool()>& done) {
    // The writer keeps up: a failed write is seen at the next step, as in a daemon with a fast disk.
    return rig.run_until([&] {
      recorder->track(*rig.machine, rig.robot, rig.clock.now_us());
      recorder->wait_idle();
      return done();
    });
  }
  bool run_to_end() {
    rig.button.press();
    const bool ended = run_until([this] {
      return !calibration::is_running(rig.status().state) && rig.status().state != CalibrationState::kIdle;
    });
    settle();
    return ended;
  }
  void settle() {
    recorder->wait_idle();
    for (std::string& message : recorder->take_messages()) messages.push_back(message);
  }
  std::string entry(int run) const { return recorder->history().entry_path(run); }
  formats::RunLog log(int run) const {
    const auto log = formats::read_run_log_toml(entry(run) + "/run.toml");
    EXPECT_TRUE(log) << log.error().message();
    return log ? *log : formats::RunLog{};
  }

  CalibrationRig rig;
  std::unique_ptr<RunRecorder> recorder;
  std::vector<std::string> messages;
};

TEST(RunRecorder, ACommittedRunKeepsItsSamplesRobotLogAndFit) {
  // GIVEN the daemon's recorder WHEN a calibration runs to its commit
  RecordedRig r;
  ASSERT_TRUE(r.run_to_end());
  ASSERT_EQ(r.rig.status().state, CalibrationState::kDone) << r.rig.status().reason;
  // THEN its entry holds the samples, the robot it used, the log and the committed fit
  const std::string entry = r.entry(1);
  EXPECT_EQ(r.rig.status().run_entry, entry);
  EXPECT_EQ(r.rig.status().run_outcome, "committed");
  const auto samples = formats::read_samples_csv(entry + "/samples.csv", kCableCount);
  ASSERT_TRUE(samples) << samples.error().message();
  EXPECT_EQ(static_cast<int>(samples->size()), r.rig.status().samples);
  const auto robot = formats::read_robot_toml(entry + "/robot.toml");
  ASSERT_TRUE(robot) << robot.error().message();
  EXPECT_EQ(robot->name, r.rig.robot.name);
  const formats::RunLog log = r.log(1);
  EXPECT_EQ(log.run, 1);
  EXPECT_EQ(log.outcome, "committed");
  EXPECT_EQ(log.calibration, r.rig.status().committed_seq);
  EXPECT_EQ(log.started, "2026-11-23T08:00:00Z");
  EXPECT_EQ(log.samples, r.rig.status().samples);
  EXPECT_EQ(log.waypoints.size(), static_cast<std::size_t>(r.rig.status().waypoint_count));
  EXPECT_GT(log.robot_time_s, 0.0);
  EXPECT_TRUE(contains(log.reason, "committed calibration")) << log.reason;
  EXPECT_EQ(store::test::file_bytes(entry + "/calibration.toml"), r.rig.current_bytes());
  EXPECT_TRUE(r.messages.empty()) << joined(r.messages);
  // AND status and show name the entry, its outcome and samples
  const auto ask = [&](const char* request) {
    return control::respond(request, *r.rig.machine, r.rig.store, r.rig.clock.now_us());
  };
  const std::string samples_text = std::to_string(r.rig.status().samples);
  EXPECT_TRUE(contains(ask("status"), "\"run\":{\"entry\":\"" + entry + "\",\"outcome\":\"committed\",\"samples\":" +
                                          samples_text + ",\"diagnosis\":\"\",\"named_terms\":[]}"))
      << ask("status");
  EXPECT_TRUE(contains(ask("show"), "\"run\":{\"entry\":\"" + entry + "\",\"outcome\":\"committed\",\"samples\":" +
                                        samples_text + ",\"skipped\":0,"))
      << ask("show");
}

TEST(RunRecorder, TheModelCheckOfARunReachesItsStatus) {
  // GIVEN the recorder with the model check on WHEN a calibration runs to its end
  RecordedRig r(1'000'000'000, DiagnosisOptions{});
  ASSERT_TRUE(r.run_to_end());
  EXPECT_EQ(r.rig.status().run_diagnosis, "");  // picked up by the next step after the check
  // THEN after the check, the next step puts the verdict of run.toml into the status
  ASSERT_TRUE(r.run_until([] { return true; }));
  const std::string verdict = r.log(1).diagnosis;
  EXPECT_FALSE(verdict.empty());
  EXPECT_EQ(r.rig.status().run_diagnosis, verdict);
  const std::string status = control::respond("status", *r.rig.machine, r.rig.store, r.rig.clock.now_us());
  EXPECT_TRUE(contains(status, ",\"diagnosis\":\"" + verdict.substr(0, 20))) << status;
}

TEST(RunRecorder, AnAbortedRunKeepsWhatItMeasured) {
  // GIVEN a run that sampled two waypoints WHEN the operator aborts it
  RecordedRig r;
  r.rig.button.press();
  ASSERT_TRUE(r.run_until([&] { return r.rig.status().samples == 2 && r.rig.status().state == CalibrationState::kMove; }));
  r.rig.machine->request_abort(r.rig.clock.now_us());
  ASSERT_TRUE(r.run_until([] { return true; }));
  r.settle();
  // THEN its entry says aborted, why, and keeps the two samples
  const formats::RunLog log = r.log(1);
  EXPECT_EQ(log.outcome, "aborted");
  EXPECT_TRUE(contains(log.reason, "abort requested")) << log.reason;
  EXPECT_EQ(log.samples, 2);
  EXPECT_FALSE(log.finished.empty());
  const auto samples = formats::read_samples_csv(r.entry(1) + "/samples.csv", kCableCount);
  ASSERT_TRUE(samples);
  EXPECT_EQ(samples->size(), 2u);
  EXPECT_FALSE(std::filesystem::exists(r.entry(1) + "/calibration.toml"));
}

TEST(RunRecorder, ARunTheDaemonDidNotFinishIsFoundInterruptedAtTheNextStart) {
  // GIVEN a daemon that dies after two waypoints (its queued writes done, the run never ended)
  RecordedRig r;
  r.rig.button.press();
  ASSERT_TRUE(r.run_until([&] { return r.rig.status().samples == 2 && r.rig.status().state == CalibrationState::kMove; }));
  r.recorder->finish();
  EXPECT_EQ(r.log(1).outcome, "running");
  // WHEN the next daemon starts
  RunRecorder next(r.rig.store.state_dir(), 1'000'000'000);
  const auto messages = next.recover("2026-11-23T09:00:00Z", "run interrupted at waypoint 3 of 6");
  // THEN the run is interrupted, with its samples kept, and the next run gets the next number
  EXPECT_TRUE(contains(joined(messages), r.entry(1) + " was interrupted")) << joined(messages);
  const formats::RunLog log = r.log(1);
  EXPECT_EQ(log.outcome, "interrupted");
  EXPECT_EQ(log.reason, "run interrupted at waypoint 3 of 6");
  EXPECT_EQ(log.samples, 2);
  EXPECT_EQ(*next.history().next_run(), 2);
}

TEST(RunRecorder, ACommittedRunGetsItsReportBesideTheFit) {
  // GIVEN the recorder as the daemon makes it (the solver's options for the report's residuals)
  RecordedRig r(1'000'000'000, std::nullopt, CalibrationOptions{});
  // WHEN a calibration runs to its commit
  ASSERT_TRUE(r.run_to_end());
  ASSERT_EQ(r.rig.status().state, CalibrationState::kDone) << r.rig.status().reason;
  // THEN report.html is in the entry: the verdict card of the fit and the run's facts
  const auto report = store::read_file(r.entry(1) + "/report.html");
  ASSERT_TRUE(report) << joined(r.messages);
  EXPECT_TRUE(contains(*report, "<!DOCTYPE html>")) << report->substr(0, 200);
  EXPECT_TRUE(contains(*report, "run time"));
  EXPECT_TRUE(contains(*report, "run-000001, committed"));
  // AND WHEN a run is aborted before its fit THEN its entry has no report
  r.rig.button.press();
  ASSERT_TRUE(r.run_until([&] { return r.rig.status().samples == 1; }));
  r.rig.machine->request_abort(r.rig.clock.now_us());
  ASSERT_TRUE(r.run_until([] { return true; }));
  r.settle();
  EXPECT_TRUE(std::filesystem::exists(r.entry(2) + "/run.toml"));
  EXPECT_FALSE(std::filesystem::exists(r.entry(2) + "/report.html"));
}

TEST(RunRecorder, TheBudgetPrunesOlderRunsButNeverTheCurrentCalibrationsNorTheLast) {
  // GIVEN a budget of nothing, a committed run and two aborted ones after it
  RecordedRig r(0);
  ASSERT_TRUE(r.run_to_end());
  ASSERT_EQ(r.rig.status().state, CalibrationState::kDone);
  const auto run_and_abort = [&r] {
    r.rig.button.press();
    ASSERT_TRUE(r.run_until([&] { return r.rig.status().samples == 1; }));
    r.rig.machine->request_abort(r.rig.clock.now_us());
    ASSERT_TRUE(r.run_until([] { return true; }));
    r.settle();
  };
  run_and_abort();
  // THEN the last run stays while it is the newest
  EXPECT_TRUE(std::filesystem::exists(r.entry(2) + "/run.toml"));
  run_and_abort();
  // THEN the older aborted run is pruned, the current calibration's run and the last stay, and the log says so
  EXPECT_TRUE(std::filesystem::exists(r.entry(1) + "/samples.csv"));
  EXPECT_FALSE(std::filesystem::exists(r.entry(2)));
  EXPECT_TRUE(std::filesystem::exists(r.entry(3) + "/run.toml"));
  EXPECT_TRUE(contains(joined(r.messages), "removed run-000002")) << joined(r.messages);
}

TEST(RunRecorder, AnEntryThatCannotBeWrittenStopsTheRunAndIsLoggedOncePerFile) {
  // GIVEN a file where the run's entry directory would go (writes below it fail, for root too)
  RecordedRig r;
  std::ofstream(r.entry(1)) << "in the way\n";
  // WHEN a calibration runs
  ASSERT_TRUE(r.run_to_end());
  // THEN it stops at its first failed write, before it moves, naming the path and errno; nothing is committed
  EXPECT_EQ(r.rig.status().state, CalibrationState::kFailed) << r.rig.status().reason;
  EXPECT_TRUE(contains(r.rig.status().reason, "store: open " + r.entry(1) + "/.robot.toml.tmp: Not a directory"))
      << r.rig.status().reason;
  EXPECT_TRUE(r.rig.previous_calibration_intact());
  EXPECT_EQ(r.rig.status().samples, 0);
  EXPECT_TRUE(r.rig.winches.all_stopped());
  // AND the failure is logged once per file with its path and errno
  const std::string log = joined(r.messages);
  EXPECT_TRUE(contains(log, r.entry(1) + "/.samples.csv.tmp: Not a directory")) << log;
  EXPECT_TRUE(contains(log, r.entry(1) + "/.run.toml.tmp: Not a directory")) << log;
  EXPECT_LE(r.messages.size(), 4u) << log;
}

}  // namespace
}  // namespace cdpr::daemon
