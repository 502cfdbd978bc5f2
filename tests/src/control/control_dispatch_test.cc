#include "src/control/control_dispatch.h"

#include <gtest/gtest.h>

#include "../calibration/calibration_rig.h"
#include "../store/store_test_support.h"
#include "../../text_contains.h"

namespace cdpr::control {
namespace {

using calibration::test::CalibrationRig;

using ::cdpr::test::contains;

std::string ask(CalibrationRig& rig, const std::string& line) {
  const std::string response = respond(line, *rig.machine, rig.store, rig.clock.now_us());
  EXPECT_EQ(response.back(), '\n');
  EXPECT_EQ(response.find('\n'), response.size() - 1) << "one line per response";
  return response;
}

TEST(ControlDispatch, StatusOfAnIdleDaemon) {
  // GIVEN a daemon that never ran WHEN asked for status THEN idle, nothing elapsed
  CalibrationRig rig;
  EXPECT_EQ(ask(rig, "status"),
            "{\"ok\":true,\"state\":\"idle\",\"running\":false,\"waypoint\":0,\"waypoints\":0,\"samples\":0,"
            "\"skipped\":0,\"progress\":0,\"elapsed_s\":null,\"strategy\":\"\",\"stop_reason\":\"\",\"sigma\":null,"
            "\"time_left_s\":null,\"reason\":\"\",\"note\":\"\",\"detail\":\"\","
            "\"device_faults\":\"\",\"committed_seq\":0,\"interrupted\":\"\",\"store_problems\":[],\"pending_commit\":false,"
            "\"run\":null,\"refit\":null,\"nodes\":[],\"operation\":null}\n");
}

// A refit service that records what it was asked and answers as told.
class FakeRefits : public RefitService {
 public:
  Expected<std::string, std::string> start_refit(int run, const std::string& terms) override {
    asked.push_back(std::to_string(run) + " " + terms);
    if (!refusal.empty()) return Unexpected{refusal};
    status = RefitStatus{"run-000003", terms, "running", "fitting", 0, ""};
    return std::string("refitting run-000003 with catenary + " + terms);
  }
  std::optional<RefitStatus> refit_status() const override { return status; }
  std::vector<std::string> asked;
  std::string refusal;
  std::optional<RefitStatus> status;
};

TEST(ControlDispatch, RefitIsHandedToTheServiceAndRefusedWhileRunning) {
  // GIVEN an idle daemon with a refit service
  CalibrationRig rig;
  FakeRefits refits;
  const auto ask_refits = [&](const std::string& line) {
    return respond(line, *rig.machine, rig.store, rig.clock.now_us(), &refits);
  };
  // WHEN a refit is requested THEN the service gets the run and the terms, and status shows its progress
  EXPECT_EQ(ask_refits("refit load_cell_bias run-000003"),
            "{\"ok\":true,\"message\":\"refitting run-000003 with catenary + load_cell_bias\"}\n");
  EXPECT_EQ(refits.asked, (std::vector<std::string>{"3 load_cell_bias"}));
  EXPECT_TRUE(contains(ask_refits("status"),
                       "\"refit\":{\"run\":\"run-000003\",\"terms\":\"load_cell_bias\",\"state\":\"running\","
                       "\"message\":\"fitting\",\"committed_seq\":0,\"entry\":\"\"},\"nodes\":[],\"operation\":null}"))
      << ask_refits("status");
  // WHEN the service refuses THEN the answer says why
  refits.refusal = "unknown term 'bias'";
  EXPECT_EQ(ask_refits("refit bias"), "{\"ok\":false,\"error\":\"refit refused: unknown term 'bias'\"}\n");
  // WHEN no service is there THEN refit is refused
  EXPECT_TRUE(contains(ask(rig, "refit load_cell_bias"), "refit refused: this daemon cannot refit runs"));
  // WHEN a calibration is running THEN refit is refused before the service is asked
  refits.refusal.clear();
  ASSERT_EQ(ask(rig, "start"), "{\"ok\":true,\"message\":\"started\"}\n");
  ASSERT_TRUE(rig.run_to(calibration::CalibrationState::kMove, 1));
  EXPECT_TRUE(contains(ask_refits("refit load_cell_bias"), "refit refused: a calibration is running"));
  EXPECT_EQ(refits.asked.size(), 2u);
}

TEST(ControlDispatch, ResetFaultsReachesTheWinchBank) {
  // GIVEN an idle daemon WHEN asked to reset the faults THEN the bank is asked to, and the answer says so
  CalibrationRig rig;
  EXPECT_EQ(ask(rig, "reset-faults"), "{\"ok\":true,\"message\":\"faults reset (there were none)\"}\n");
  EXPECT_EQ(rig.winches.fault_resets(), 1);
}

TEST(ControlDispatch, StartTwiceAbortAndRollbackWhileRunning) {
  // GIVEN a daemon started over the socket
  CalibrationRig rig;
  EXPECT_EQ(ask(rig, "start"), "{\"ok\":true,\"message\":\"started\"}\n");
  ASSERT_TRUE(rig.run_to(calibration::CalibrationState::kMove, 2));
  // WHEN started again, rolled back, then aborted
  const std::string again = ask(rig, "start");
  const std::string rollback = ask(rig, "rollback 1");
  const std::string status = ask(rig, "status");
  const std::string abort = ask(rig, "abort");
  // THEN the second start and the rollback are refused, status shows the waypoint, abort stops the run
  EXPECT_TRUE(contains(again, "\"ok\":false") && contains(again, "already running")) << again;
  EXPECT_TRUE(contains(rollback, "rollback refused: a calibration is running")) << rollback;
  EXPECT_TRUE(contains(status, "\"state\":\"move\",\"running\":true,\"waypoint\":2,\"waypoints\":6")) << status;
  EXPECT_TRUE(contains(abort, "\"ok\":true") && contains(abort, "abort requested on the control socket")) << abort;
  EXPECT_TRUE(rig.winches.all_stopped());
  EXPECT_TRUE(rig.previous_calibration_intact());
  EXPECT_TRUE(contains(ask(rig, "abort"), "abort ignored: no calibration running"));
}

TEST(ControlDispatch, ShowHistoryAndRollbackAfterACalibration) {
  // GIVEN a completed calibration on top of the previous one
  CalibrationRig rig;
  ask(rig, "start");
  ASSERT_TRUE(rig.run_to_end());
  // WHEN show, history and rollback 1 are asked
  const std::string show = ask(rig, "show");
  const std::string history = ask(rig, "history");
  const std::string rollback = ask(rig, "rollback 1");
  // THEN show gives the new calibration, history both versions, and the rollback restores the old bytes
  EXPECT_TRUE(contains(show, "\"present\":true,\"seq\":2,\"created\":\"2026-11-23T08:00:00Z\"")) << show;
  EXPECT_TRUE(contains(show, "\"winches\":[{\"anchor\":[0.03,0,50]")) << show;
  EXPECT_TRUE(contains(history, "{\"seq\":2,\"current\":true") && contains(history, "{\"seq\":1,\"current\":false"))
      << history;
  EXPECT_EQ(rollback, "{\"ok\":true,\"message\":\"calibration 1 is current\"}\n");
  EXPECT_TRUE(rig.previous_calibration_intact());
  EXPECT_TRUE(contains(ask(rig, "rollback 9"), "rollback to 9 failed: open"));
}

TEST(ControlDispatch, ShowListsTheRejectedReadingsAndTheModelWarning) {
  // GIVEN a clean committed calibration WHEN shown THEN no warning and no rejected reading
  CalibrationRig rig;
  EXPECT_TRUE(ask(rig, "show").ends_with(",\"model_warning\":\"\",\"rejected\":[],\"run\":null}\n"));
  // AND GIVEN a committed calibration.toml with two [[rejected]] readings and a model_warning
  Calibration calibration = store::test::calibration_version(2);
  calibration.rejected = {{12, SensorKind::kEncoder, 3, -95.4}, {24, SensorKind::kForce, 0, 8.25}};
  calibration.model_warning = "the model does not fit the data: chi-square 912.3 for 614 degrees of freedom";
  ASSERT_TRUE(rig.store.commit(calibration));
  // WHEN shown THEN both follow the fit, each reading with row, sensor, cable and residual in sigmas
  const std::string show = ask(rig, "show");
  EXPECT_TRUE(show.ends_with(
      "\"rms_force\":4.8},\"model_warning\":\"the model does not fit the data: chi-square 912.3 for 614 degrees "
      "of freedom\",\"rejected\":[{\"row\":12,\"sensor\":\"encoder\",\"cable\":3,\"residual\":-95.4},"
      "{\"row\":24,\"sensor\":\"force\",\"cable\":0,\"residual\":8.25}],\"run\":null}\n"))
      << show;
  // AND GIVEN a row whose load cell and encoder 2 are one suspect group WHEN shown THEN both carry the group
  calibration.rejected = {{24, SensorKind::kForce, 0, 8.25, 1}, {24, SensorKind::kEncoder, 2, 6.5, 1}};
  ASSERT_TRUE(rig.store.commit(calibration));
  const std::string grouped = ask(rig, "show");
  // AND name the group's members in words, for calibctl show
  EXPECT_TRUE(contains(grouped, "{\"row\":24,\"sensor\":\"force\",\"cable\":0,\"residual\":8.25,\"group\":1,"
                                "\"group_members\":\"force or encoder cable 2\"},"
                                "{\"row\":24,\"sensor\":\"encoder\",\"cable\":2,\"residual\":6.5,\"group\":1,"
                                "\"group_members\":\"force or encoder cable 2\"}]"))
      << grouped;
}

TEST(ControlDispatch, GarbageGetsAnErrorLine) {
  // GIVEN bytes that are no request WHEN sent THEN a JSON error line comes back
  CalibrationRig rig;
  const std::string response = ask(rig, "\xff\xfe{\"json\":1}");
  EXPECT_TRUE(contains(response, "{\"ok\":false,\"error\":\"request contains a non-ASCII")) << response;
}

}  // namespace
}  // namespace cdpr::control
