// The waypoint jobs handed to the owner (WaypointWork::kByOwner): while the
// planning or the choice of the next waypoint is away, every step still polls
// the drives (the CANopen master's heartbeat goes out there) and checks for
// faults; a fault or an abort meanwhile ends the run and the job delivered
// later is dropped; the run is the same as with the jobs inline.

#include "src/calibration/calibration_state_machine.h"

#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "calibration_rig.h"
#include "../../text_contains.h"

namespace cdpr::calibration {
namespace {

CalibratorOptions sequential_options() {
  CalibratorOptions options = test::rig_options();
  options.planner.grid_xy = 4;
  options.strategy = WaypointStrategy::kSequential;
  options.sequential.max_count = 8;
  return options;
}

// The drives quick-stop after 500 ms without an update(), as the shipped
// consumer_heartbeat_ms does.
fakes::FakeWinchBank::Options watched_winches() {
  fakes::FakeWinchBank::Options options = test::fast_winches();
  options.consumer_heartbeat_us = 500'000;
  return options;
}

// A rig whose machine hands its waypoint jobs to the test.
struct OwnerRig {
  explicit OwnerRig(const CalibratorOptions& options) : rig(options) {
    rig.winches = fakes::FakeWinchBank(watched_winches());
    EXPECT_TRUE(rig.winches.open().ok());
    rig.use_model_tension();
    machine = std::make_unique<CalibrationStateMachine>(
        rig.robot, CalibratorDevices{rig.winches, rig.load_cell, rig.pose, nullptr, rig.store}, options,
        [](const Robot& robot, const std::vector<Sample>& samples) { return test::good_fit(robot, samples); },
        [] { return std::string("2026-11-23T08:00:00Z"); }, WaypointWork::kByOwner);
    rig.active = machine.get();
  }
  void step() {
    rig.clock.advance_us(test::kStepUs);
    machine->step(rig.clock.now_us());
  }
  // Steps until a job waits for the owner; false when the run ended first.
  bool step_to_job() {
    for (int k = 0; k < 1'000'000 && !machine->waypoint_job_pending(); ++k) {
      if (!is_running(machine->status().state)) return false;
      step();
    }
    return machine->waypoint_job_pending();
  }
  test::CalibrationRig rig;
  std::unique_ptr<CalibrationStateMachine> machine;
};

TEST(WaypointJobs, WhileAJobIsAwayEveryStepStillPollsTheDrivesAndTheRunIsTheInlineOne) {
  // GIVEN the sequential strategy, drives that quick-stop after 500 ms
  // without the master's heartbeat, and the waypoint jobs handed to the owner
  OwnerRig owner(sequential_options());
  ASSERT_TRUE(owner.machine->request_start(owner.rig.clock.now_us()));
  // WHEN every job stays away for 50 steps (1 s) before it is run and delivered
  int jobs = 0;
  int resolving_steps = 0;
  while (owner.step_to_job()) {
    const CalibrationState state = owner.machine->status().state;
    WaypointJob job = owner.machine->take_waypoint_job();
    ++jobs;
    const int updates = owner.rig.winches.updates();
    for (int k = 0; k < 50; ++k) {
      owner.step();
      // THEN meanwhile the machine waits in its state, says why, and polls the drives every step
      ASSERT_EQ(owner.machine->status().state, state) << owner.machine->status().reason;
      ASSERT_TRUE(owner.machine->status().detail == "planning" ||
                  owner.machine->status().detail == "choosing the next waypoint")
          << owner.machine->status().detail;
    }
    EXPECT_EQ(owner.rig.winches.updates(), updates + 50);
    if (state == CalibrationState::kSample) resolving_steps += 50;
    job.run();
    owner.machine->deliver_waypoint_job(std::move(job), owner.rig.clock.now_us());
  }
  for (int k = 0; k < 1'000'000 && is_running(owner.machine->status().state); ++k) owner.step();
  // AND the drives never lost the heartbeat, and the run committed
  EXPECT_EQ(owner.rig.winches.heartbeat_losses(), 0);
  EXPECT_EQ(owner.rig.winches.quick_stops(), 0);
  EXPECT_EQ(owner.machine->status().state, CalibrationState::kDone) << owner.machine->status().reason;
  EXPECT_GT(resolving_steps, 0);
  // AND it sampled the waypoints the same run with inline jobs samples
  test::CalibrationRig inline_rig(sequential_options());
  inline_rig.use_model_tension();
  ASSERT_TRUE(inline_rig.machine->request_start(inline_rig.clock.now_us()));
  ASSERT_TRUE(inline_rig.run_to_end());
  ASSERT_EQ(inline_rig.status().state, CalibrationState::kDone) << inline_rig.status().reason;
  ASSERT_EQ(owner.machine->samples().size(), inline_rig.machine->samples().size());
  EXPECT_EQ(jobs, 1 + static_cast<int>(owner.machine->samples().size()) + owner.machine->status().skipped);
  for (std::size_t k = 0; k < owner.machine->samples().size(); ++k) {
    EXPECT_LT((owner.machine->samples()[k].position_world - inline_rig.machine->samples()[k].position_world).norm(),
              1e-9)
        << "sample " << k;
  }
}

TEST(WaypointJobs, AFaultWhileTheNextWaypointIsChosenStopsTheRunAndTheJobIsDropped) {
  // GIVEN a run whose choice of the next waypoint is away (after its second sample)
  OwnerRig owner(sequential_options());
  ASSERT_TRUE(owner.machine->request_start(owner.rig.clock.now_us()));
  WaypointJob job;
  for (int jobs = 0; jobs < 3; ++jobs) {
    ASSERT_TRUE(owner.step_to_job()) << owner.machine->status().reason;
    job = owner.machine->take_waypoint_job();
    if (jobs < 2) {
      job.run();
      owner.machine->deliver_waypoint_job(std::move(job), owner.rig.clock.now_us());
    }
  }
  ASSERT_EQ(owner.machine->status().state, CalibrationState::kSample);
  // WHEN a winch's node falls silent meanwhile
  owner.rig.winches.silence(2);
  for (int k = 0; k < 100 && is_running(owner.machine->status().state); ++k) owner.step();
  // THEN the monitor ends the run with a quick stop while the job is still away
  EXPECT_EQ(owner.machine->status().state, CalibrationState::kFailed);
  EXPECT_TRUE(::cdpr::test::contains(owner.machine->status().reason, "winch 2")) << owner.machine->status().reason;
  EXPECT_GE(owner.rig.winches.quick_stops(), 1);
  EXPECT_TRUE(owner.rig.winches.all_stopped());
  EXPECT_TRUE(owner.machine->waypoint_job_out());
  // AND no new run starts before the job is back
  owner.rig.winches.silence(2, false);
  EXPECT_FALSE(owner.machine->request_start(owner.rig.clock.now_us()));
  EXPECT_TRUE(::cdpr::test::contains(owner.machine->status().note, "still finishing")) << owner.machine->status().note;
  // AND the job delivered late is dropped: the run stays failed, nothing
  // moves; the run's waypoints are its record again
  EXPECT_TRUE(owner.machine->plan().waypoints.empty());
  job.run();
  owner.machine->deliver_waypoint_job(std::move(job), owner.rig.clock.now_us());
  owner.step();
  EXPECT_EQ(owner.machine->status().state, CalibrationState::kFailed);
  EXPECT_EQ(owner.machine->samples().size(), 2u);
  EXPECT_FALSE(owner.machine->plan().waypoints.empty());
  EXPECT_EQ(owner.machine->current_waypoint(), nullptr);
  EXPECT_FALSE(owner.machine->waypoint_job_out());
  EXPECT_TRUE(owner.machine->request_start(owner.rig.clock.now_us()));
}

TEST(WaypointJobs, AnAbortDuringPlanningHaltsAndDropsThePlan) {
  // GIVEN a run whose planning is away
  OwnerRig owner(test::rig_options());
  ASSERT_TRUE(owner.machine->request_start(owner.rig.clock.now_us()));
  ASSERT_TRUE(owner.step_to_job());
  ASSERT_EQ(owner.machine->status().state, CalibrationState::kPlan);
  WaypointJob job = owner.machine->take_waypoint_job();
  owner.step();
  EXPECT_EQ(owner.machine->status().detail, "planning");
  // (the drives are enabled only once the plan exists)
  EXPECT_EQ(owner.rig.winches.enables(), 0);
  const int halts = owner.rig.winches.halts();
  // WHEN the operator aborts, and the plan is delivered afterwards
  ASSERT_TRUE(owner.machine->request_abort(owner.rig.clock.now_us()));
  job.run();
  ASSERT_TRUE(job.problem.empty()) << job.problem;
  owner.machine->deliver_waypoint_job(std::move(job), owner.rig.clock.now_us());
  for (int k = 0; k < 100; ++k) owner.step();
  // THEN the winches were halted, the run ended aborted, and the plan was dropped
  EXPECT_EQ(owner.rig.winches.halts(), halts + 1);
  EXPECT_EQ(owner.machine->status().state, CalibrationState::kAborted);
  EXPECT_EQ(owner.machine->run_log().outcome, formats::kRunAborted);
  EXPECT_EQ(owner.machine->status().waypoint_count, 0);
  EXPECT_EQ(owner.machine->status().waypoint, 0);
  EXPECT_TRUE(owner.rig.winches.all_stopped());
  EXPECT_EQ(owner.rig.winches.enables(), 0);
}

TEST(WaypointJobs, TheDrivesAreEnabledOnceThePlanExists) {
  // GIVEN a run whose planning is away
  OwnerRig owner(test::rig_options());
  ASSERT_TRUE(owner.machine->request_start(owner.rig.clock.now_us()));
  ASSERT_TRUE(owner.step_to_job());
  WaypointJob job = owner.machine->take_waypoint_job();
  // WHEN the plan comes back after a while
  for (int k = 0; k < 50; ++k) owner.step();
  EXPECT_EQ(owner.rig.winches.enables(), 0);
  job.run();
  owner.machine->deliver_waypoint_job(std::move(job), owner.rig.clock.now_us());
  // THEN the drives are enabled then, and the run moves once they report enabled
  EXPECT_EQ(owner.rig.winches.enables(), 1);
  EXPECT_EQ(owner.machine->status().state, CalibrationState::kPlan);
  EXPECT_EQ(owner.machine->status().detail, "enabling drives");
  for (int k = 0; k < 100 && owner.machine->status().state == CalibrationState::kPlan; ++k) owner.step();
  EXPECT_EQ(owner.machine->status().state, CalibrationState::kMove) << owner.machine->status().reason;
  EXPECT_EQ(owner.machine->status().waypoint, 1);
}

TEST(WaypointJobs, AnInfeasiblePlanFailsTheRunWithTheDrivesNeverEnabled) {
  // GIVEN a tension band no waypoint can meet
  CalibratorOptions options = test::rig_options();
  options.planner.min_tension_n = 1e6;
  options.planner.max_tension_n = 2e6;
  test::CalibrationRig rig(options);
  // WHEN a run starts
  ASSERT_TRUE(rig.machine->request_start(rig.clock.now_us()));
  ASSERT_TRUE(rig.run_to_end());
  // THEN it fails in planning without a drive ever enabled
  EXPECT_EQ(rig.status().state, CalibrationState::kFailed);
  EXPECT_TRUE(::cdpr::test::contains(rig.status().reason, "plan: ")) << rig.status().reason;
  EXPECT_EQ(rig.winches.enables(), 0);
}

}  // namespace
}  // namespace cdpr::calibration
