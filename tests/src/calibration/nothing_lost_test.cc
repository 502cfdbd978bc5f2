// Nothing lost (state machine and control requests against fakes): a store
// that cannot be written stops a run before anything moves; a commit that
// fails keeps the fit and its samples in pending/ and `commit` commits them
// once the cause is fixed; unreadable stored files show in the status; an
// abort's message replaces older notes.

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "../store/test_broken_directory.h"
#include "calibration_rig.h"
#include "src/control/control_dispatch.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/samples_csv.h"
#include "src/store/pending_calibration.h"
#include "../../text_contains.h"

namespace cdpr::calibration {
namespace {

using store::test::BrokenDirectory;
using test::CalibrationRig;

using ::cdpr::test::contains;

std::string ask(CalibrationRig& rig, const std::string& line) {
  return control::respond(line, *rig.machine, rig.store, rig.clock.now_us());
}

TEST(NothingLost, AStoreThatCannotBeWrittenStopsTheRunBeforeAnythingMoves) {
  // GIVEN a store whose history directory cannot take files
  CalibrationRig rig;
  BrokenDirectory broken(rig.store.history_dir());
  // WHEN a calibration is started
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  // THEN it fails in preflight saying why, and the drives were never enabled
  EXPECT_EQ(rig.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(contains(rig.status().reason, "the store cannot be written (open " + rig.store.history_dir() +
                                                "/.write-probe.tmp: Not a directory): a fit could not be committed"))
      << rig.status().reason;
  EXPECT_TRUE(contains(rig.status().reason, "(during preflight)")) << rig.status().reason;
  EXPECT_EQ(rig.winches.enables(), 0);
  EXPECT_TRUE(rig.winches.all_stopped());
}

TEST(NothingLost, AFailedCommitKeepsTheFitAndSamplesAndCommitRetriesIt) {
  // GIVEN a run that reached its commit, when the history directory breaks
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to(CalibrationState::kCommit));
  auto broken = std::make_unique<BrokenDirectory>(rig.store.history_dir());
  // WHEN the commit runs
  ASSERT_TRUE(rig.run_to_end());
  // THEN the run fails, saying where the fit and its samples are kept, and the old calibration is current
  EXPECT_EQ(rig.status().state, CalibrationState::kFailed);
  const store::PendingCalibration pending(rig.store.state_dir());
  EXPECT_TRUE(contains(rig.status().reason, "the fit and its 6 samples are kept in " + pending.dir() +
                                                ": fix the cause, then `calibctl commit`"))
      << rig.status().reason;
  EXPECT_TRUE(rig.previous_calibration_intact());
  EXPECT_TRUE(rig.status().pending_commit);
  EXPECT_TRUE(contains(ask(rig, "status"), "\"pending_commit\":true"));
  // AND the kept files hold the fit and the 6 samples
  const auto samples = formats::read_samples_csv(pending.dir() + "/samples.csv", 4);
  ASSERT_TRUE(samples) << samples.error().message();
  EXPECT_EQ(samples->size(), 6u);
  const auto fit = formats::read_calibration_toml(pending.dir() + "/calibration.toml");
  ASSERT_TRUE(fit) << fit.error().message();
  EXPECT_EQ(fit->samples, 6);

  // AND WHEN `commit` is asked while the cause is still there THEN it fails again and keeps them
  const std::string again = ask(rig, "commit");
  EXPECT_TRUE(contains(again, "\"ok\":false") && contains(again, "failed again")) << again;
  EXPECT_TRUE(pending.exists());
  // AND WHEN the cause is fixed and `commit` asked THEN the kept fit becomes current and pending/ goes
  broken.reset();
  const std::string committed = ask(rig, "commit");
  EXPECT_TRUE(contains(committed, "\"ok\":true") && contains(committed, "committed calibration 2")) << committed;
  EXPECT_EQ(rig.current_bytes(), store::test::file_bytes(rig.store.history_dir() + "/" +
                                                           store::CalibrationStore::history_name(2)));
  EXPECT_FALSE(pending.exists());
  EXPECT_FALSE(rig.status().pending_commit);
  EXPECT_TRUE(contains(ask(rig, "commit"), "nothing to commit"));
}

TEST(NothingLost, AFitThatNeitherCommitsNorFitsInPendingStaysInMemoryUntilCommitted) {
  // GIVEN a run at its commit, when neither the history nor pending/ can take a file (a full disk)
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to(CalibrationState::kCommit));
  auto broken = std::make_unique<BrokenDirectory>(rig.store.history_dir());
  const store::PendingCalibration pending(rig.store.state_dir());
  std::ofstream(pending.dir()) << "in the way\n";
  // WHEN the commit runs
  ASSERT_TRUE(rig.run_to_end());
  // THEN the run fails saying the fit is kept in memory, the old calibration is current, no temp file is left
  EXPECT_EQ(rig.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(contains(rig.status().reason, "keeping the fit in " + pending.dir() + " failed too")) << rig.status().reason;
  EXPECT_TRUE(contains(rig.status().reason, "the fit is kept in memory until the daemon stops")) << rig.status().reason;
  EXPECT_TRUE(rig.previous_calibration_intact());
  EXPECT_TRUE(rig.status().pending_commit);
  EXPECT_FALSE(std::filesystem::exists(rig.store.state_dir() + "/.calibration.toml.tmp"));
  // AND WHEN `commit` is asked while the disk is still full THEN it says exactly why not
  const std::string again = ask(rig, "commit");
  EXPECT_TRUE(contains(again, "commit of the fit kept in memory failed again: list " + rig.store.history_dir() +
                                  ": Not a directory"))
      << again;
  // AND WHEN the space is back THEN `commit` commits the fit from memory
  broken.reset();
  std::filesystem::remove(pending.dir());
  const std::string committed = ask(rig, "commit");
  EXPECT_TRUE(contains(committed, "\"ok\":true") && contains(committed, "committed calibration 2 from memory"))
      << committed;
  const auto current = rig.store.load_current();
  ASSERT_TRUE(current && *current);
  EXPECT_EQ((*current)->seq, 2);
  EXPECT_EQ((*current)->calibration.samples, 6);
  // AND the headline says so, and nothing is left to commit
  EXPECT_EQ(rig.status().state, CalibrationState::kDone);
  EXPECT_FALSE(rig.status().pending_commit);
  EXPECT_TRUE(contains(ask(rig, "commit"), "nothing to commit"));
}

TEST(NothingLost, NothingToCommitSaysHowTheLastRunEnded) {
  // GIVEN a run that stopped before its fit (a winch fault)
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(2));
  rig.winches.silence(1);
  ASSERT_TRUE(rig.run_to_end());
  // WHEN `commit` is asked THEN it says there is no fit and why: how the last run ended
  const std::string answer = ask(rig, "commit");
  EXPECT_TRUE(contains(answer, "nothing to commit: no fit is kept in " + rig.store.state_dir() +
                                   "/pending nor in memory (the last run: failed: "))
      << answer;
}

TEST(NothingLost, ACommitOutsideARunReplacesTheFailedHeadline) {
  // GIVEN a run that failed
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(2));
  rig.winches.silence(1);
  ASSERT_TRUE(rig.run_to_end());
  ASSERT_EQ(rig.status().state, CalibrationState::kFailed);
  // WHEN the owner commits a refit of its samples (calibctl commit --with-term)
  rig.machine->note_commit(2, "by the refit of run-000001 with the terms load_cell_bias (operator's choice)",
                           rig.clock.now_us());
  // THEN the headline says what is current now
  EXPECT_EQ(rig.status().state, CalibrationState::kDone);
  EXPECT_EQ(rig.status().committed_seq, 2);
  EXPECT_EQ(rig.status().reason,
            "committed calibration 2 by the refit of run-000001 with the terms load_cell_bias (operator's choice)");
  EXPECT_EQ(rig.status().run_outcome, "failed");  // the run itself stays as its run.toml says
}

TEST(NothingLost, AnUnreadableCurrentCalibrationIsCheckedAgainstTheNewestReadableVersion) {
  // GIVEN calibration.toml cut short, version 1 readable in the history, and a change limit no fit can meet
  CalibratorOptions options = test::rig_options();
  options.validation.max_anchor_change_m = 1e-9;
  CalibrationRig rig(options);
  const std::string text = rig.current_bytes();
  std::ofstream(rig.store.current_path(), std::ios::trunc) << text.substr(0, text.size() / 3);
  // WHEN a run is made
  rig.button.press();
  ASSERT_TRUE(rig.run_to(CalibrationState::kPlan));
  EXPECT_TRUE(contains(rig.status().note, "checking the change against history version 1")) << rig.status().note;
  ASSERT_TRUE(rig.run_to_end());
  // THEN its fit is held to the change check against version 1 (and refused here)
  EXPECT_EQ(rig.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(contains(rig.status().reason, "fit refused")) << rig.status().reason;
}

TEST(NothingLost, UnreadableStoredFilesShowInStatusAndShow) {
  // GIVEN calibration.toml cut short (as by a full disk under a non-atomic writer)
  CalibrationRig rig;
  const std::string text = rig.current_bytes();
  std::ofstream(rig.store.current_path(), std::ios::trunc) << text.substr(0, text.size() / 3);
  // WHEN the owner checks the store (as the daemon does at start)
  rig.machine->refresh_store_problems();
  // THEN status names the problem, and show says the calibration is unreadable
  const std::string status = ask(rig, "status");
  EXPECT_TRUE(contains(status, "\"store_problems\":[\"the current calibration is unreadable (parse " +
                                   rig.store.current_path()))
      << status;
  EXPECT_TRUE(contains(ask(rig, "show"), "the current calibration is unreadable: parse")) << ask(rig, "show");
  // AND a start keeps reporting it
  rig.machine->request_start(rig.clock.now_us());
  EXPECT_EQ(rig.status().store_problems.size(), 1u);
}

TEST(NothingLost, AfterAnAbortTheNoteIsTheAbortsMessage) {
  // GIVEN a run in which waypoint 2 was skipped (a note about it)
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to(CalibrationState::kSettle, 2));
  rig.swinging = true;
  ASSERT_TRUE(rig.run_to(CalibrationState::kMove, 3));
  ASSERT_TRUE(contains(rig.status().note, "waypoint 2 skipped")) << rig.status().note;
  // WHEN the operator aborts
  ask(rig, "abort");
  // THEN the run ends "aborted" as its run.toml says, and the note is the abort's, not the skipped waypoint's
  EXPECT_EQ(rig.status().state, CalibrationState::kAborted);
  EXPECT_EQ(rig.status().run_outcome, "aborted");
  EXPECT_TRUE(contains(rig.status().note, "abort requested on the control socket (during move, waypoint 3/6)"))
      << rig.status().note;
  EXPECT_FALSE(contains(rig.status().note, "skipped")) << rig.status().note;
}

}  // namespace
}  // namespace cdpr::calibration
