// Component tests of the calibration state machine against behavioural fakes
// and an injected clock: every fault ends with the winches stopped, a clear
// reason, and the previous calibration intact byte for byte.

#include "src/calibration/calibration_state_machine.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "calibration_rig.h"
#include "src/formats/calibration_toml.h"
#include "../../text_contains.h"

namespace cdpr::calibration {
namespace {

using test::CalibrationRig;

using ::cdpr::test::contains;

// The common end of every fault test.
void expect_failed_safely(const CalibrationRig& rig, const std::string& reason_words,
                          CalibrationState end = CalibrationState::kFailed) {
  EXPECT_EQ(rig.status().state, end);
  EXPECT_TRUE(contains(rig.status().reason, reason_words)) << rig.status().reason;
  EXPECT_TRUE(contains(rig.status().reason, "previous calibration kept")) << rig.status().reason;
  EXPECT_TRUE(rig.winches.all_stopped());
  EXPECT_TRUE(rig.previous_calibration_intact());
  EXPECT_EQ(rig.status().committed_seq, 0);
}

TEST(CalibrationStateMachine, OneButtonPressRunsTheWholeCalibrationAndCommits) {
  // GIVEN a robot at rest and a stored calibration
  CalibrationRig rig;
  // WHEN the button is pressed once
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  // THEN every waypoint was sampled, one solve ran, and a new calibration is current
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
  EXPECT_EQ(rig.status().waypoint_count, 6);
  EXPECT_EQ(rig.status().samples, 6);
  EXPECT_EQ(rig.status().skipped, 0);
  EXPECT_DOUBLE_EQ(rig.status().progress, 1.0);
  EXPECT_EQ(rig.solves, 1);
  EXPECT_EQ(rig.status().committed_seq, 2);
  const auto current = rig.store.load_current();
  ASSERT_TRUE(current && current->has_value());
  EXPECT_EQ((*current)->calibration.created, "2026-11-23T08:00:00Z");
  EXPECT_EQ((*current)->calibration.samples, 6);
  EXPECT_NE(rig.current_bytes(), rig.previous_bytes);
  // AND the winches hold still, and the owner may service the bus again
  EXPECT_TRUE(rig.winches.all_stopped());
  EXPECT_FALSE(rig.machine->owns_hardware());
}

TEST(CalibrationStateMachine, SamplesAreTheRestPosesAndEncoders) {
  // GIVEN a full run
  CalibrationRig rig;
  ASSERT_TRUE(rig.machine->request_start(rig.clock.now_us()));
  ASSERT_TRUE(rig.run_to_end());
  // WHEN the samples are compared with the plan
  const auto& samples = rig.machine->samples();
  ASSERT_EQ(samples.size(), rig.machine->plan().waypoints.size());
  // THEN each sample is its waypoint's rest position, target payouts and tension
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Waypoint& waypoint = rig.machine->plan().waypoints[k];
    EXPECT_LT((samples[k].position_world - waypoint.rest.world_T_platform.position_world).norm(), 1e-9);
    for (int i = 0; i < kCableCount; ++i) EXPECT_NEAR(samples[k].encoder_m[i], waypoint.payout_m[i], 1e-3);
    EXPECT_DOUBLE_EQ(samples[k].force_n, 300.0);
    EXPECT_EQ(samples[k].id, static_cast<int>(k));
  }
}

TEST(CalibrationStateMachine, TheSequentialStrategyChoosesWaypointsUntilItsStopRule) {
  // GIVEN the sequential strategy, at most 8 samples, consistent tensions
  CalibratorOptions options = test::rig_options();
  options.strategy = WaypointStrategy::kSequential;
  options.sequential.max_count = 8;
  CalibrationRig rig(options);
  rig.use_model_tension();
  // WHEN a run goes to the end
  ASSERT_TRUE(rig.machine->request_start(rig.clock.now_us()));
  ASSERT_TRUE(rig.run_until([&] { return rig.status().state == CalibrationState::kSettle; }));
  // THEN while it runs, the status names the strategy and the targets
  EXPECT_EQ(rig.status().strategy, "sequential");
  EXPECT_EQ(rig.status().waypoint_count, 8);
  EXPECT_DOUBLE_EQ(rig.status().target_anchor_sigma_m, 0.02);
  ASSERT_TRUE(rig.run_to_end());
  // AND it commits, having stopped by its rule after at least the rows validation needs
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
  EXPECT_FALSE(rig.status().stop_reason.empty());
  EXPECT_GE(rig.status().samples, options.validation.min_samples);
  EXPECT_LE(rig.status().samples, 8);
  EXPECT_GT(rig.status().largest_anchor_sigma_m, 0.0);
  // AND every sample is one candidate's rest pose, none twice
  std::vector<int> seen;
  for (const Sample& sample : rig.machine->samples()) {
    int match = -1;
    const auto& candidates = rig.machine->plan().waypoints;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if ((sample.position_world - candidates[k].rest.world_T_platform.position_world).norm() < 1e-9) match = static_cast<int>(k);
    }
    ASSERT_GE(match, 0);
    EXPECT_EQ(std::count(seen.begin(), seen.end(), match), 0);
    seen.push_back(match);
  }
  // AND calibration.toml and the run log say how the run went
  const auto current = rig.store.load_current();
  ASSERT_TRUE(current && current->has_value());
  ASSERT_TRUE((*current)->calibration.run.has_value());
  EXPECT_EQ((*current)->calibration.run->strategy, "sequential");
  EXPECT_EQ((*current)->calibration.run->waypoints, rig.status().samples);
  EXPECT_EQ((*current)->calibration.run->stop, rig.status().stop_reason);
  EXPECT_EQ(rig.machine->run_log().strategy, "sequential");
  EXPECT_EQ(rig.machine->run_log().stop, rig.status().stop_reason);
}

TEST(CalibrationStateMachine, EncoderNodeSilentStopsTheRun) {
  // GIVEN a run moving to waypoint 2
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(2));
  // WHEN winch 2's node falls silent
  rig.winches.silence(2);
  ASSERT_TRUE(rig.run_to_end());
  // THEN the run fails naming the winch, stopped, old calibration intact
  expect_failed_safely(rig, "winch 2 node silent");
  EXPECT_GE(rig.winches.quick_stops(), 1);
}

TEST(CalibrationStateMachine, ModbusTimeoutsStopTheRun) {
  // GIVEN a run moving to waypoint 3
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(3));
  // WHEN the load cell stops answering
  rig.load_cell.fail_always(hal::Status(hal::ErrorCode::kTimeout, "load cell 127.0.0.1:1502: no reply after 3 tries"));
  ASSERT_TRUE(rig.run_to_end());
  // THEN the reason names the load cell and the timeout
  expect_failed_safely(rig, "load cell: timeout: load cell 127.0.0.1:1502");
}

TEST(CalibrationStateMachine, AFewCrcErrorsAreToleratedRepeatedOnesAreNot) {
  // GIVEN a run in progress with the default tolerance of 3 failed reads in a row
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to(CalibrationState::kSettle, 2));
  // WHEN 3 reads in a row fail with CRC errors
  const hal::Status crc(hal::ErrorCode::kCorruptData, "load cell RTU /dev/ttyUSB0: CRC mismatch");
  rig.load_cell.fail_next(crc, 3);
  // THEN the run goes on to the end
  ASSERT_TRUE(rig.run_to_end());
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;

  // GIVEN a second run WHEN 4 reads in a row fail THEN it stops
  CalibrationRig second;
  second.button.press();
  ASSERT_TRUE(second.run_to(CalibrationState::kSettle, 2));
  second.load_cell.fail_next(crc, 4);
  ASSERT_TRUE(second.run_to_end());
  expect_failed_safely(second, "corrupt data: load cell RTU /dev/ttyUSB0: CRC mismatch (4 failed reads in a row)");
}

TEST(CalibrationStateMachine, StalePoseStopsTheRun) {
  // GIVEN a run moving to waypoint 2
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(2));
  const hal::TimeUs stopped_us = rig.clock.now_us();
  // WHEN the pose stream stops
  rig.pose.set_streaming(false);
  ASSERT_TRUE(rig.run_to_end());
  // THEN the run fails as soon as the pose is older than the limit
  expect_failed_safely(rig, "pose stale");
  EXPECT_LE(rig.status().finished_us - stopped_us, test::rig_options().monitor.pose_stale_us + 2 * test::kStepUs);
}

TEST(CalibrationStateMachine, LostTrackingStopsTheRun) {
  // GIVEN a run moving
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(2));
  // WHEN the localization reports tracking lost
  rig.pose.set_generator([&rig](hal::TimeUs now_us) {
    hal::PoseSample sample = rig.platform(now_us);
    sample.valid = false;
    return sample;
  });
  ASSERT_TRUE(rig.run_to_end());
  // THEN the run stops naming it
  expect_failed_safely(rig, "tracking lost");
}

TEST(CalibrationStateMachine, TensionOutOfLimitsStopsTheRun) {
  // GIVEN a run moving to waypoint 4
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(4));
  // WHEN the reference tension exceeds its maximum
  rig.load_cell.set_tension(6000.0, true);
  ASSERT_TRUE(rig.run_to_end());
  // THEN the reason gives the tension and the limits
  expect_failed_safely(rig, "tension out of limits: 6000 N outside [20, 5000] N");
}

TEST(CalibrationStateMachine, ButtonPressedTwiceIsIgnoredNotARestart) {
  // GIVEN a run at waypoint 3
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to(CalibrationState::kSettle, 3));
  const hal::TimeUs started_us = rig.status().started_us;
  // WHEN the button is pressed again
  rig.button.press();
  rig.clock.advance_us(test::kStepUs);
  rig.machine->step(rig.clock.now_us());
  // THEN it is noted and ignored: same run, same waypoint
  EXPECT_TRUE(contains(rig.status().note, "start ignored: a calibration is already running (settle, waypoint 3/6)"))
      << rig.status().note;
  EXPECT_EQ(rig.status().started_us, started_us);
  EXPECT_EQ(rig.status().waypoint, 3);
  EXPECT_TRUE(rig.machine->owns_hardware());
  // AND the run completes normally
  ASSERT_TRUE(rig.run_to_end());
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
  EXPECT_EQ(rig.status().samples, 6);
}

TEST(CalibrationStateMachine, AbortMidRunHaltsAndKeepsTheOldCalibration) {
  // GIVEN a run moving to waypoint 3
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to_moving(3));
  // WHEN an abort is requested
  EXPECT_TRUE(rig.machine->request_abort(rig.clock.now_us()));
  // THEN the winches are halted at once, the reason says so, nothing was committed
  expect_failed_safely(rig, "abort requested (during move, waypoint 3/6)", CalibrationState::kAborted);
  EXPECT_GE(rig.winches.halts(), 1);
  // AND further steps leave everything stopped
  rig.run_until([] { return false; }, 2'000'000);
  EXPECT_TRUE(rig.winches.all_stopped());
  // AND the run is shown "aborted", as its run.toml says
  EXPECT_EQ(rig.status().state, CalibrationState::kAborted);
  EXPECT_EQ(to_string(rig.status().state), std::string("aborted"));
  EXPECT_EQ(rig.machine->run_log().outcome, formats::kRunAborted);
}

TEST(CalibrationStateMachine, FailureDuringCommitKeepsTheOldCalibrationByteForByte) {
  for (int crash_step = 1; crash_step < store::CalibrationStore::kCommitReplacedStep; ++crash_step) {
    SCOPED_TRACE("store stops after step " + std::to_string(crash_step));
    // GIVEN a run whose commit is interrupted before the rename of calibration.toml
    CalibrationRig rig;
    rig.store.set_crash_hook([crash_step](int step) { return step == crash_step; });
    // WHEN the run reaches the commit
    rig.button.press();
    ASSERT_TRUE(rig.run_to_end());
    // THEN it fails naming the store, and a reopened store loads the old file, byte for byte
    expect_failed_safely(rig, "store: crash");
    store::CalibrationStore reopened({rig.state_dir.path(), 5});
    ASSERT_TRUE(reopened.open());
    const auto current = reopened.load_current();
    ASSERT_TRUE(current && current->has_value());
    EXPECT_EQ((*current)->text, rig.previous_bytes);
  }
}

TEST(CalibrationStateMachine, ASettleTimeoutSkipsTheWaypoint) {
  // GIVEN a platform that keeps swinging at waypoint 2 only
  CalibrationRig rig;
  rig.button.press();
  ASSERT_TRUE(rig.run_to(CalibrationState::kSettle, 2));
  rig.swinging = true;
  // WHEN the settle timeout passes
  ASSERT_TRUE(rig.run_to(CalibrationState::kMove, 3));
  rig.swinging = false;
  // THEN waypoint 2 is skipped with a note, and the run completes with one sample fewer
  EXPECT_TRUE(contains(rig.status().note, "waypoint 2 skipped: no equilibrium within 10 s (platform moving"))
      << rig.status().note;
  ASSERT_TRUE(rig.run_to_end());
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
  EXPECT_EQ(rig.status().skipped, 1);
  EXPECT_EQ(rig.status().samples, 5);
}

TEST(CalibrationStateMachine, TooManySkippedWaypointsFailTheRun) {
  // GIVEN a platform that never comes to rest
  CalibrationRig rig;
  rig.swinging = true;
  // WHEN a run is started
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  // THEN it fails for lack of samples, without solving
  expect_failed_safely(rig, "only 0 of 6 waypoints settled (at least 4 needed)");
  EXPECT_EQ(rig.solves, 0);
}

TEST(CalibrationStateMachine, SolveFailureKeepsTheOldCalibration) {
  // GIVEN a solver that fails
  CalibrationRig rig;
  rig.solve = [](const Robot&, const std::vector<Sample>&) {
    CalibrationResult result;
    result.message = "not evaluable at the initial point";
    return result;
  };
  // WHEN a run completes its waypoints
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  // THEN it fails with the solver's message
  expect_failed_safely(rig, "fit refused: solve failed: not evaluable at the initial point");
}

TEST(CalibrationStateMachine, AnImplausibleFitIsRefused) {
  // GIVEN a solver whose anchors jumped 2 m from the stored calibration
  CalibrationRig rig;
  rig.solve = [](const Robot& robot, const std::vector<Sample>& samples) {
    CalibrationResult result = test::good_fit(robot, samples);
    result.calibration.winches[1].anchor_world.z() -= 2.0;
    return result;
  };
  // WHEN the run completes THEN the fit is refused naming the cable
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  expect_failed_safely(rig, "cable 1: anchor moved 2 m since the previous calibration");
}

TEST(CalibrationStateMachine, PreflightRefusesWithoutAPose) {
  // GIVEN a pose source that sends nothing
  CalibrationRig rig;
  rig.pose.set_streaming(false);
  // WHEN started THEN it fails in preflight once the first-contact wait is over, drives never enabled
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  expect_failed_safely(rig, "pose stale: no pose received (during preflight)");
  EXPECT_GE(rig.status().finished_us - rig.status().started_us, test::rig_options().first_contact_timeout_us);
  EXPECT_EQ(rig.winches.enables(), 0);
}

TEST(CalibrationStateMachine, PreflightWaitsForAPoseThatArrivesLate) {
  // GIVEN a pose tracker still starting up when the button is pressed
  CalibrationRig rig;
  rig.pose.set_streaming(false);
  rig.button.press();
  // THEN for a second preflight waits and says for what, without enabling the drives
  EXPECT_FALSE(rig.run_until([&] { return rig.status().state != CalibrationState::kPreflight; }, 1'000'000));
  EXPECT_EQ(rig.status().detail, "waiting for first contact: pose");
  EXPECT_EQ(rig.winches.enables(), 0);
  // WHEN the poses start to arrive THEN the run goes on to the end
  rig.pose.set_streaming(true);
  ASSERT_TRUE(rig.run_to_end());
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
}

TEST(CalibrationStateMachine, ANodeHeardBeforeAndNowSilentIsAFaultAtOnce) {
  // GIVEN winch 3's node heard at start-up, silent when the button is pressed
  CalibrationRig rig;
  ASSERT_TRUE(rig.winches.update(rig.clock.now_us()).ok());
  rig.winches.silence(3);
  rig.button.press();
  // WHEN started THEN preflight does not wait for it: a node that stopped talking is a fault
  ASSERT_TRUE(rig.run_to_end());
  expect_failed_safely(rig, "winch 3 node silent (last heard");
  EXPECT_LT(rig.status().finished_us - rig.status().started_us, test::rig_options().first_contact_timeout_us);
}

TEST(CalibrationStateMachine, PreflightFailsWhenADriveDoesNotEnable) {
  // GIVEN winch 1 in drive fault
  CalibrationRig rig;
  rig.winches.inject_fault(1);
  // WHEN started THEN preflight names the drive
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  expect_failed_safely(rig, "winch 1 drive fault");
}

TEST(CalibrationStateMachine, DeviceFaultsShowUntilTheOperatorResetsThem) {
  // GIVEN a run that failed on winch 1's drive fault
  CalibrationRig rig;
  rig.winches.inject_fault(1);
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  rig.machine->step(rig.clock.now_us());
  // THEN the status shows the latched fault, and keeps showing it
  EXPECT_EQ(rig.machine->status().device_faults, "winch 1: drive fault");
  for (int k = 0; k < 10; ++k) rig.machine->step(rig.clock.now_us());
  EXPECT_EQ(rig.machine->status().device_faults, "winch 1: drive fault");
  // WHEN the operator resets the faults THEN the bank is asked to, and the status clears
  ASSERT_TRUE(rig.machine->request_reset_faults(rig.clock.now_us()));
  EXPECT_EQ(rig.winches.fault_resets(), 1);
  EXPECT_NE(rig.machine->status().note.find("were: winch 1: drive fault"), std::string::npos) << rig.machine->status().note;
  rig.machine->step(rig.clock.now_us());
  EXPECT_EQ(rig.machine->status().device_faults, "");
  // AND during a run the request is refused
  rig.button.press();
  rig.machine->step(rig.clock.now_us());
  ASSERT_TRUE(is_running(rig.machine->status().state));
  EXPECT_FALSE(rig.machine->request_reset_faults(rig.clock.now_us()));
  EXPECT_NE(rig.machine->status().note.find("refused"), std::string::npos);
}

TEST(CalibrationStateMachine, AsynchronousSolveIsHandedInByTheOwner) {
  // GIVEN a state machine without a solve function
  CalibrationRig rig;
  CalibrationStateMachine machine(rig.robot, CalibratorDevices{rig.winches, rig.load_cell, rig.pose, nullptr, rig.store},
                                  test::rig_options(), nullptr, nullptr);
  rig.active = &machine;  // the platform physics follows this machine's waypoints
  // WHEN it is started and run until it waits for the solver
  ASSERT_TRUE(machine.request_start(rig.clock.now_us()));
  for (int k = 0; k < 1'000'000 && !machine.solve_pending() && is_running(machine.status().state); ++k) {
    rig.clock.advance_us(test::kStepUs);
    machine.step(rig.clock.now_us());
  }
  // THEN it waits, and commits the delivered result
  ASSERT_TRUE(machine.solve_pending()) << machine.status().reason;
  machine.step(rig.clock.now_us());
  EXPECT_EQ(machine.status().detail, "waiting for the solver");
  machine.deliver_solve_result(test::good_fit(rig.robot, machine.samples()), rig.clock.now_us());
  machine.step(rig.clock.now_us());
  machine.step(rig.clock.now_us());
  EXPECT_EQ(machine.status().state, CalibrationState::kDone) << machine.status().reason;
}

}  // namespace
}  // namespace cdpr::calibration
