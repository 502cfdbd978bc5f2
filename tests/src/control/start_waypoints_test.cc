// `start waypoints <path> [<run>]` through the control dispatch, on the
// state machine's rig of fakes (tests/src/calibration/calibration_rig.h):
// what is refused before anything moves, and that a run drives exactly the
// waypoints given, after an earlier run's rows when asked.
#include <fstream>

#include <gtest/gtest.h>

#include "../calibration/calibration_rig.h"
#include "../../text_contains.h"
#include "src/control/control_dispatch.h"
#include "src/formats/robot_toml.h"
#include "src/formats/run_log_toml.h"
#include "src/formats/samples_csv.h"
#include "src/formats/waypoints_csv.h"
#include "src/store/run_history.h"

namespace cdpr::control {
namespace start_waypoints_test {

using calibration::CalibrationState;
using calibration::test::CalibrationRig;
using ::cdpr::test::contains;

std::string ask(CalibrationRig& rig, const std::string& line) {
  return respond(line, *rig.machine, rig.store, rig.clock.now_us());
}

std::string write_file(const CalibrationRig& rig, const std::string& name, const std::string& text) {
  const std::string path = rig.state_dir.path() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// The planner's feasible and rejected candidates on the rig's robot (its
// stored calibration: nominal anchors, offsets 2 m), on a finer grid.
calibration::WaypointPlan candidates(const CalibrationRig& rig) {
  calibration::PlannerOptions options = calibration::test::rig_options().planner;
  options.grid_xy = 8;
  options.grid_z = 4;
  std::array<double, kCableCount> offsets;
  offsets.fill(2.0);
  return calibration::candidate_waypoints(rig.robot, offsets, options);
}

std::vector<formats::PlannedWaypoint> feasible_positions(const CalibrationRig& rig, std::size_t count) {
  const calibration::WaypointPlan plan = candidates(rig);
  std::vector<formats::PlannedWaypoint> chosen;
  // Every fifth: apart from each other, not the grid's first corner only.
  for (std::size_t k = 0; k < plan.waypoints.size() && chosen.size() < count; k += 5) {
    chosen.push_back({plan.waypoints[k].rest.world_T_platform.position_world, 1.0});
  }
  EXPECT_EQ(chosen.size(), count);
  return chosen;
}

std::string waypoints_file(const CalibrationRig& rig, const std::vector<formats::PlannedWaypoint>& waypoints) {
  return write_file(rig, "waypoints.csv", formats::format_waypoints_csv(waypoints, "test waypoints"));
}

// History entry `run` as a daemon keeps it, with `samples` measured on `robot`.
void keep_run(const CalibrationRig& rig, int run, const Robot& robot, const std::vector<Sample>& samples) {
  const store::RunHistory history(rig.store.history_dir());
  ASSERT_TRUE(history.create(run));
  formats::RunLog log;
  log.run = run;
  log.outcome = formats::kRunFailed;
  log.robot = robot.name;
  log.started = "2026-11-22T10:00:00Z";
  log.samples = static_cast<int>(samples.size());
  ASSERT_TRUE(history.write(run, store::RunHistory::kRobotName, formats::format_robot_toml(robot)));
  ASSERT_TRUE(history.write(run, store::RunHistory::kSamplesName, formats::format_samples_csv(samples)));
  ASSERT_TRUE(history.write(run, store::RunHistory::kLogName, formats::format_run_log_toml(log)));
}

void expect_idle_and_untouched(const CalibrationRig& rig) {
  EXPECT_EQ(rig.status().state, CalibrationState::kIdle);
  for (int i = 0; i < rig.winches.winch_count(); ++i) EXPECT_FALSE(rig.winches.moving(i));
}

TEST(StartWaypoints, ARunDrivesExactlyTheWaypointsGivenInTheirOrder) {
  // GIVEN a waypoints file of four feasible poses
  CalibrationRig rig;
  const auto given = feasible_positions(rig, 4);
  const std::string path = waypoints_file(rig, given);
  // WHEN a run is started through it
  const std::string answer = ask(rig, "start waypoints " + path);
  EXPECT_TRUE(contains(answer, "\"ok\":true")) << answer;
  EXPECT_TRUE(contains(answer, "started: 4 waypoints from " + path)) << answer;
  ASSERT_TRUE(rig.run_to_end());
  // THEN it samples exactly those poses, in the file's order, and commits as a planned run would
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
  EXPECT_EQ(rig.status().strategy, "given");
  EXPECT_EQ(rig.machine->run_log().waypoints_planned, 4);
  ASSERT_EQ(rig.machine->samples().size(), given.size());
  for (std::size_t k = 0; k < given.size(); ++k) {
    EXPECT_LT((rig.machine->samples()[k].position_world - given[k].position_world).norm(), 1e-9) << k;
  }
}

TEST(StartWaypoints, AnAbortStopsARunThroughAFileAsAPlannedOne) {
  // GIVEN a run through four waypoints, the winches travelling to the second
  CalibrationRig rig;
  ASSERT_TRUE(contains(ask(rig, "start waypoints " + waypoints_file(rig, feasible_positions(rig, 4))), "\"ok\":true"));
  ASSERT_TRUE(rig.run_to_moving(2));
  // WHEN the operator aborts THEN the winches stop, the run ends aborted, the old calibration stays
  EXPECT_TRUE(contains(ask(rig, "abort"), "\"ok\":true"));
  EXPECT_EQ(rig.status().state, CalibrationState::kAborted);
  EXPECT_GE(rig.winches.halts(), 1);
  rig.run_until([] { return false; }, 2'000'000);
  EXPECT_TRUE(rig.winches.all_stopped());
  EXPECT_TRUE(rig.previous_calibration_intact());
  // AND a plain start afterwards plans again (the file is not remembered)
  ASSERT_TRUE(contains(ask(rig, "start"), "\"ok\":true"));
  ASSERT_TRUE(rig.run_to(CalibrationState::kMove, 1));
  EXPECT_EQ(rig.status().strategy, "spread");
}

TEST(StartWaypoints, AppendedToARunTheDataAreItsRowsThenTheNewPoses) {
  // GIVEN a kept run of five rows of this robot, and a file of two feasible poses
  CalibrationRig rig;
  std::vector<Sample> earlier(5);
  for (int k = 0; k < 5; ++k) {
    earlier[k].id = k;
    earlier[k].position_world = Eigen::Vector3d(100.0 + k, 100.0, 20.0);
    earlier[k].encoder_m = {10.0 + k, 11.0, 12.0, 13.0};
    earlier[k].force_n = 400.0;
  }
  keep_run(rig, 3, rig.robot, earlier);
  const auto given = feasible_positions(rig, 2);
  // WHEN a run through the file is started, appended to run-000003
  const std::string answer = ask(rig, "start waypoints " + waypoints_file(rig, given) + " run-000003");
  EXPECT_TRUE(contains(answer, "after the 5 samples of run 3")) << answer;
  ASSERT_TRUE(rig.run_to_end());
  // THEN its samples are the five kept rows followed by the two new poses, ids going on
  const std::vector<Sample>& samples = rig.machine->samples();
  ASSERT_EQ(samples.size(), 7u) << rig.status().reason;
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(samples[k].position_world, earlier[k].position_world);
    EXPECT_EQ(samples[k].id, k);
  }
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT((samples[5 + k].position_world - given[k].position_world).norm(), 1e-9);
    EXPECT_EQ(samples[5 + k].id, 5 + k);
  }
  // AND its log names the run it extends; the fit saw all seven (validation's 4 met)
  EXPECT_EQ(rig.machine->run_log().extends, 3);
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
}

TEST(StartWaypoints, AMissingOrMalformedFileIsRefusedNamingFileLineAndColumn) {
  CalibrationRig rig;
  // GIVEN no file WHEN started through it THEN refused with the path and why, nothing moves
  const std::string missing = rig.state_dir.path() + "/none.csv";
  EXPECT_TRUE(contains(ask(rig, "start waypoints " + missing),
                       "{\"ok\":false,\"error\":\"start refused: " + missing +
                           ": No such file or directory (the daemon reads it as its own user in its sandbox"));
  expect_idle_and_untouched(rig);
  // GIVEN a file whose second row has a word for z THEN refused at that line and column
  const std::string bad = write_file(rig, "bad.csv", "x,y,z\n120,110,20\n120,110,high\n");
  EXPECT_EQ(ask(rig, "start waypoints " + bad),
            "{\"ok\":false,\"error\":\"start refused: " + bad + ":3: z: 'high' is not a finite number\"}\n");
  // GIVEN a directory, not a file THEN refused
  EXPECT_TRUE(contains(ask(rig, "start waypoints " + rig.state_dir.path()), "not a regular file"));
  expect_idle_and_untouched(rig);
}

TEST(StartWaypoints, TooFewRowsForTheFitEndTheRunAfterMeasuringThemCountingTheEarlierRows) {
  // GIVEN validation needs 4 rows, a kept run of one row and a file of two poses
  CalibrationRig rig;
  std::vector<Sample> earlier(1);
  earlier[0].position_world = Eigen::Vector3d(100.0, 100.0, 20.0);
  keep_run(rig, 5, rig.robot, earlier);
  const std::string path = waypoints_file(rig, feasible_positions(rig, 2));
  // WHEN the file alone is run THEN the run fails after both were sampled, saying how many settled
  ASSERT_TRUE(contains(ask(rig, "start waypoints " + path), "\"ok\":true"));
  ASSERT_TRUE(rig.run_to_end());
  EXPECT_EQ(rig.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(contains(rig.status().reason, "only 2 of 2 waypoints settled (at least 4 needed) (")) << rig.status().reason;
  // AND appended to run 5 the earlier row counts, and the reason says so
  ASSERT_TRUE(contains(ask(rig, "start waypoints " + path + " 5"), "\"ok\":true"));
  ASSERT_TRUE(rig.run_to_end());
  EXPECT_TRUE(contains(rig.status().reason,
                       "only 2 of 2 waypoints settled (at least 4 needed, counting the 1 rows of run 5) ("))
      << rig.status().reason;
  EXPECT_EQ(rig.machine->samples().size(), 3u);
}

TEST(StartWaypoints, AWaypointOutsideTheWorkspaceRefusesTheWholeRequest) {
  // GIVEN a file whose second waypoint is above the z band (5..35 m)
  CalibrationRig rig;
  auto given = feasible_positions(rig, 3);
  given[1].position_world.z() = 48.0;
  // WHEN started through it THEN refused naming that waypoint and why; no run
  const std::string answer = ask(rig, "start waypoints " + waypoints_file(rig, given));
  EXPECT_TRUE(contains(answer, "start refused: ")) << answer;
  EXPECT_TRUE(contains(answer, "waypoint 2 of 3: z 48 m outside the workspace [5, 35] m")) << answer;
  expect_idle_and_untouched(rig);
}

TEST(StartWaypoints, AWaypointOutsideThePlannersLimitsFailsTheRunBeforeTheDrivesAreEnabled) {
  // GIVEN a file of a feasible pose and then one in the box the planner rejects (tension, sag or no rest)
  CalibrationRig rig;
  const calibration::WaypointPlan plan = candidates(rig);
  ASSERT_FALSE(plan.rejected.empty());
  const calibration::RejectedWaypoint& infeasible = plan.rejected.front();
  std::vector<formats::PlannedWaypoint> given = feasible_positions(rig, 1);
  given.push_back({infeasible.position_world, 0.0});
  // WHEN a run is started through it
  ASSERT_TRUE(contains(ask(rig, "start waypoints " + waypoints_file(rig, given)), "\"ok\":true"));
  ASSERT_TRUE(rig.run_to_end());
  // THEN the run fails in plan naming the second waypoint and the planner's reason; no drive was enabled
  EXPECT_EQ(rig.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(contains(rig.status().reason, "plan: waypoint 2 of 2 (")) << rig.status().reason;
  EXPECT_TRUE(contains(rig.status().reason, infeasible.reason)) << rig.status().reason << " / " << infeasible.reason;
  EXPECT_TRUE(rig.machine->samples().empty());
  for (int i = 0; i < rig.winches.winch_count(); ++i) {
    EXPECT_NE(rig.winches.status(i).drive, hal::DriveState::kEnabled);
  }
  EXPECT_TRUE(rig.previous_calibration_intact());
}

TEST(StartWaypoints, AnUnknownOrForeignRunIsRefused) {
  CalibrationRig rig;
  const std::string path = waypoints_file(rig, feasible_positions(rig, 2));
  // GIVEN no run 9 kept WHEN appended to it THEN refused naming the run and the history
  EXPECT_TRUE(contains(ask(rig, "start waypoints " + path + " 9"),
                       "start refused: no such run: run-000009 is not in " + rig.store.history_dir()));
  // GIVEN run 4 measured on another robot THEN refused naming both robots
  Robot other = rig.robot;
  other.name = "small";
  keep_run(rig, 4, other, std::vector<Sample>(3));
  EXPECT_TRUE(contains(ask(rig, "start waypoints " + path + " 4"),
                       "start refused: run-000004 was measured on robot 'small', this daemon calibrates 'large'"));
  expect_idle_and_untouched(rig);
}

}  // namespace start_waypoints_test
}  // namespace cdpr::control
