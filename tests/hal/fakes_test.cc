// The behavioural fakes of tests/fakes/ behave like the hardware they stand
// for: the daemon's component tests rely on it.

#include <gtest/gtest.h>

#include "../fakes/fake_button.h"
#include "../fakes/fake_load_cell.h"
#include "../fakes/fake_pose_source.h"
#include "../fakes/fake_winch_bank.h"
#include "../fakes/manual_clock.h"

namespace cdpr::fakes {
namespace {

// Updates `bank` every `step_ms` for `duration_ms` of injected time.
void run(FakeWinchBank& bank, ManualClock& clock, int duration_ms, int step_ms = 10) {
  for (int t = 0; t < duration_ms; t += step_ms) {
    clock.advance_ms(step_ms);
    ASSERT_TRUE(bank.update(clock.now_us()).ok());
  }
}

TEST(FakeWinchBank, MovesTowardsTargetAtItsSpeedAndReportsFinished) {
  // GIVEN an open, enabled bank at 0.5 m/s with winch 0 at 1.0 m
  ManualClock clock;
  FakeWinchBank bank;
  bank.set_payout(0, 1.0);
  ASSERT_TRUE(bank.open().ok());
  ASSERT_TRUE(bank.enable().ok());
  ASSERT_TRUE(bank.update(clock.now_us()).ok());
  ASSERT_EQ(bank.status(0).drive, hal::DriveState::kEnabled);
  // WHEN winch 0 is sent to 1.4 m and 0.4 s pass
  ASSERT_TRUE(bank.set_target_payout(0, 1.4).ok());
  EXPECT_FALSE(bank.motion_finished());
  run(bank, clock, 400);
  // THEN it is half way (0.2 m moved), still moving
  EXPECT_NEAR(bank.status(0).payout_m, 1.2, 1e-9);
  EXPECT_FALSE(bank.motion_finished());
  EXPECT_TRUE(bank.moving(0));
  // WHEN another 0.5 s pass THEN it arrived and the bank reports finished
  run(bank, clock, 500);
  EXPECT_NEAR(bank.status(0).payout_m, 1.4, 1e-9);
  EXPECT_TRUE(bank.motion_finished());
  EXPECT_TRUE(bank.all_stopped());
}

TEST(FakeWinchBank, SilentNodeIsDeadAfterHeartbeatTimeout) {
  // GIVEN an enabled bank
  ManualClock clock;
  FakeWinchBank bank;
  ASSERT_TRUE(bank.open().ok());
  ASSERT_TRUE(bank.enable().ok());
  run(bank, clock, 50);
  ASSERT_TRUE(bank.status(2).alive);
  // WHEN node 2 goes silent for less, then more, than the 300 ms timeout
  bank.silence(2);
  run(bank, clock, 200);
  EXPECT_TRUE(bank.status(2).alive);
  run(bank, clock, 200);
  // THEN it is dead, its age grew, and targets for it are refused
  EXPECT_FALSE(bank.status(2).alive);
  EXPECT_GT(bank.status(2).heartbeat_age_us, 300'000);
  EXPECT_EQ(bank.set_target_payout(2, 1.0).code(), hal::ErrorCode::kInvalidState);
  EXPECT_FALSE(bank.motion_finished());
}

TEST(FakeWinchBank, QuickStopStopsAtOnce) {
  // GIVEN a winch moving to a far target
  ManualClock clock;
  FakeWinchBank bank;
  ASSERT_TRUE(bank.open().ok());
  ASSERT_TRUE(bank.enable().ok());
  run(bank, clock, 10);
  ASSERT_TRUE(bank.set_target_payout(1, 5.0).ok());
  run(bank, clock, 100);
  ASSERT_FALSE(bank.all_stopped());
  // WHEN quick-stopped
  ASSERT_TRUE(bank.quick_stop().ok());
  const double stopped_at_m = bank.status(1).payout_m;
  run(bank, clock, 500);
  // THEN it did not move further and is in quick stop
  EXPECT_TRUE(bank.all_stopped());
  EXPECT_DOUBLE_EQ(bank.status(1).payout_m, stopped_at_m);
  EXPECT_EQ(bank.status(1).drive, hal::DriveState::kQuickStop);
  EXPECT_EQ(bank.quick_stops(), 1);
}

TEST(FakeLoadCell, ReportsTensionAndInjectedErrorsInOrder) {
  // GIVEN an open cell at 900 N with two timeouts queued
  ManualClock clock(1000);
  FakeLoadCell cell(clock);
  ASSERT_TRUE(cell.open().ok());
  cell.set_tension(900.0, false);
  cell.fail_next(hal::Status(hal::ErrorCode::kTimeout, "t"), 2);
  // WHEN read three times THEN two timeouts, then the stamped value
  EXPECT_EQ(cell.read().status().code(), hal::ErrorCode::kTimeout);
  EXPECT_EQ(cell.read().status().code(), hal::ErrorCode::kTimeout);
  const auto sample = cell.read();
  ASSERT_TRUE(sample.ok());
  EXPECT_DOUBLE_EQ(sample.value().tension_n, 900.0);
  EXPECT_FALSE(sample.value().stable);
  EXPECT_EQ(sample.value().time_us, 1000);
}

TEST(FakePoseSource, GoesStaleWhenStreamStops) {
  // GIVEN a streaming source
  ManualClock clock;
  FakePoseSource pose(clock);
  ASSERT_TRUE(pose.open().ok());
  pose.set_pose({1.0, 2.0, 3.0});
  clock.advance_ms(10);
  ASSERT_TRUE(pose.update(0).ok());
  ASSERT_TRUE(pose.latest().has_value());
  EXPECT_EQ(pose.latest()->received_us, 10'000);
  EXPECT_DOUBLE_EQ(pose.latest()->platform_world.z, 3.0);
  // WHEN the stream stops and time passes
  pose.set_streaming(false);
  clock.advance_ms(500);
  ASSERT_TRUE(pose.update(0).ok());
  // THEN the latest sample keeps its old arrival time
  EXPECT_EQ(clock.now_us() - pose.latest()->received_us, 500'000);
}

TEST(FakeButton, CountsPressesOnce) {
  FakeButton button;
  button.press();
  button.press();
  const auto first = button.take_presses();
  ASSERT_TRUE(first.ok());
  EXPECT_EQ(first.value(), 2);
  EXPECT_EQ(button.take_presses().value(), 0);
}

}  // namespace
}  // namespace cdpr::fakes
