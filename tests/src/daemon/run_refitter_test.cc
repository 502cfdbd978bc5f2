// The refit of a kept run with an extra model term (run_refitter.h): every
// request that cannot be served is refused at once with its reason, one
// refit at a time, and a fit that does not validate, or ends while a
// calibration runs, commits nothing. (A refit that validates and commits:
// tests/integration/hidden_effect_run_test.cc, on the virtual robot.)

#include "src/daemon/run_refitter.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "../../solver/model/test_robots.h"
#include "../store/store_test_support.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"
#include "../../text_contains.h"

namespace cdpr::daemon {
namespace {

using ::cdpr::test::contains;

class RefitRig {
 public:
  RefitRig() : store({dir.path(), 10}), history(store.history_dir()) {
    EXPECT_TRUE(store.open());
    refitter = std::make_unique<RunRefitter>(robot, store.history_dir(), store, CalibrationOptions{},
                                             calibration::ValidationLimits{}, [] { return "2026-11-27T03:00:00Z"; },
                                             [this](const std::string& line) { log.push_back(line); });
  }
  // Entry `run` with a log and, as asked, robot.toml and `samples` rows.
  void keep_run(int run, int samples, const Robot& of_robot, bool with_samples_file = true) {
    ASSERT_TRUE(history.create(run));
    formats::RunLog log;
    log.run = run;
    log.outcome = formats::kRunFailed;
    log.robot = of_robot.name;
    log.started = "2026-11-27T02:00:00Z";
    log.samples = samples;
    ASSERT_TRUE(history.write(run, store::RunHistory::kLogName, formats::format_run_log_toml(log)));
    ASSERT_TRUE(history.write(run, store::RunHistory::kRobotName, formats::format_robot_toml(of_robot)));
    if (!with_samples_file) return;
    std::vector<Sample> rows;
    for (int k = 0; k < samples; ++k) {
      rows.push_back(cdpr::test::sample_at(cdpr::test::tilted_pose(Eigen::Vector3d(60.0 + 10 * k, 50.0 + 7 * (k % 5), 20.0))));
      rows.back().id = k;
    }
    ASSERT_TRUE(history.write(run, store::RunHistory::kSamplesName, formats::format_samples_csv(rows)));
  }
  std::string refused(int run, const std::string& terms) {
    const auto started = refitter->start_refit(run, terms);
    EXPECT_FALSE(started) << *started;
    return started ? std::string() : started.error();
  }
  // Polls until the worker's fit is taken.
  void wait_for_end(bool calibration_running) {
    for (int k = 0; k < 6000 && !refitter->poll(calibration_running); ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  store::test::TempStateDir dir;
  Robot robot = cdpr::test::large_robot();
  store::CalibrationStore store;
  store::RunHistory history;
  std::vector<std::string> log;
  std::unique_ptr<RunRefitter> refitter;
};

TEST(RunRefitter, RequestsThatCannotBeServedAreRefusedWithTheirReason) {
  // GIVEN a history with a run without samples file, one with an empty one, one of another robot
  RefitRig r;
  EXPECT_TRUE(contains(r.refused(0, "load_cell_bias"), "no run is kept in " + r.store.history_dir()));
  r.keep_run(1, 0, r.robot, false);
  r.keep_run(2, 0, r.robot);
  Robot other = cdpr::test::small_robot();
  r.keep_run(3, 12, other);
  // WHEN refits are asked for THEN each refusal names what is wrong
  std::string known;  // every term of the catalogue (solver/model/effects.h), in its order
  for (const EffectDescriptor& term : kEffectCatalogue) known += (known.empty() ? "" : ", ") + std::string(term.name);
  EXPECT_TRUE(known.starts_with("elasticity, encoder_scale, load_cell, com_offset, density_error, pulley_radius, "
                                "load_cell_bias"));
  EXPECT_EQ(r.refused(1, "bias"), "unknown model term 'bias' (known: " + known + ")");
  EXPECT_TRUE(contains(r.refused(1, "load_cell_bias,"), "unknown model term ''"));
  EXPECT_TRUE(contains(r.refused(1, "load_cell,load_cell_bias"), "cannot be fitted together"));
  EXPECT_EQ(r.refused(9, "load_cell_bias"), "no such run: run-000009 is not in " + r.store.history_dir());
  EXPECT_EQ(r.refused(1, "load_cell_bias"), "run-000001 kept no samples (it ended before its first waypoint)");
  EXPECT_TRUE(contains(r.refused(2, "load_cell_bias"), "run-000002 cannot be refitted: " + r.history.entry_path(2) +
                                                          "/samples.csv:2: no data rows"));
  EXPECT_EQ(r.refused(0, "load_cell_bias"), "run-000003 was measured on robot 'small', this daemon calibrates 'large'");
  // AND nothing started, nothing was committed
  EXPECT_FALSE(r.refitter->refit_status());
  EXPECT_FALSE(r.refitter->busy());
  EXPECT_FALSE(*r.store.load_current());
}

TEST(RunRefitter, OneRefitAtATimeAndNothingCommittedWhenACalibrationStartedMeanwhile) {
  // GIVEN a kept run of the daemon's robot
  RefitRig r;
  r.keep_run(4, 12, r.robot);
  // WHEN its refit is started THEN the answer and the status say what is being fitted
  const auto started = r.refitter->start_refit(4, "load_cell_bias");
  ASSERT_TRUE(started) << started.error();
  EXPECT_EQ(*started, "refitting run-000004 (12 samples) with catenary + load_cell_bias; `calibctl status` shows "
                      "the outcome");
  EXPECT_EQ(r.refitter->refit_status()->state, "running");
  // AND a second one is refused while it runs
  EXPECT_EQ(r.refused(4, "elasticity"), "a refit of run-000004 is already running");
  // WHEN it ends while a calibration runs THEN it is refused and nothing is committed
  r.wait_for_end(true);
  EXPECT_EQ(r.refitter->refit_status()->state, "refused");
  EXPECT_TRUE(contains(r.refitter->refit_status()->message, "a calibration started while run-000004 was refitted"));
  EXPECT_FALSE(r.refitter->take_committed());
  EXPECT_FALSE(*r.store.load_current());
  ASSERT_EQ(r.log.size(), 2u);
  EXPECT_TRUE(contains(r.log[1], "refit of run-000004 refused: not committed")) << r.log[1];
}

TEST(RunRefitter, AFitThatDoesNotValidateCommitsNothing) {
  // GIVEN a kept run whose readings no model explains
  RefitRig r;
  r.keep_run(5, 12, r.robot);
  // WHEN it is refitted with a term
  ASSERT_TRUE(r.refitter->start_refit(0, "elasticity"));
  r.wait_for_end(false);
  // THEN the fit fails or validation refuses it, and the store is as it was
  const control::RefitStatus status = *r.refitter->refit_status();
  EXPECT_TRUE(status.state == "refused" || status.state == "failed") << status.state << ": " << status.message;
  EXPECT_EQ(status.committed_seq, 0);
  EXPECT_FALSE(r.refitter->take_committed());
  EXPECT_FALSE(*r.store.load_current());
}

}  // namespace
}  // namespace cdpr::daemon
