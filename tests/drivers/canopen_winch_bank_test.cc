// Loopback: the CANopen winch bank against the virtual robot's simulated
// CiA 402 drives and CiA 406 encoders (their own object dictionaries from
// the profiles' defaults, written without the master's code) on the far end
// of a real Unix stream socket pair, time stepped by the test.

#include "drivers/can/canopen_winch_bank.h"

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "drivers/can/fd_can_transport.h"
#include "fake_canopen_bus.h"

namespace cdpr::drivers::can {
namespace {

constexpr double kEncoderMPerCount = 1e-4;  // 0.1 mm per encoder count
constexpr double kDriveMPerCount = 2e-4;    // fake gearing: 2 encoder counts per drive count

CanWinchBankConfig two_winches() {
  CanWinchBankConfig config;
  config.winches = {{1, 11, kEncoderMPerCount, kDriveMPerCount}, {2, 12, kEncoderMPerCount, kDriveMPerCount}};
  config.heartbeat_timeout_us = 500'000;
  config.drive.profile_velocity_mps = 4.0;  // 20000 drive counts/s
  config.drive.profile_acceleration_mps2 = 40.0;
  config.drive.profile_deceleration_mps2 = 40.0;
  config.drive.quick_stop_deceleration_mps2 = 40.0;
  config.drive.pdo_event_timer_us = 10'000;
  config.encoder.pdo_event_timer_us = 10'000;
  return config;
}

class CanopenWinchBankTest : public ::testing::Test {
 protected:
  // The bus with two winches whose drives start from `drive` defaults.
  void start(const CanWinchBankConfig& config = two_winches(), const virtual_robot::DriveDefaults& drive = {},
             const virtual_robot::EncoderDefaults& encoder = {}) {
    int fds[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
    bus_ = std::make_unique<test::FakeCanopenBus>(fds[1], drive, encoder);
    bus_->add(1, 11);
    bus_->add(2, 12);
    const int bank_fd = fds[0];
    bank_ = std::make_unique<CanopenWinchBank>(config, [bank_fd]() -> hal::Result<std::unique_ptr<CanTransport>> {
      return std::unique_ptr<CanTransport>(std::make_unique<FdCanTransport>(bank_fd, "test bank"));
    });
  }

  // Steps the fake nodes and the bank every 5 ms for `duration_ms`; the
  // bank only while `master_alive`.
  void run_ms(int duration_ms, bool master_alive = true) {
    for (int t = 0; t < duration_ms; t += 5) {
      now_us_ += 5'000;
      bus_->step(now_us_);
      if (master_alive) {
        ASSERT_TRUE(bank_->update(now_us_).ok());
      }
    }
  }

  // Opens the bank and runs until both winches are alive (configured).
  void open_and_configure() {
    ASSERT_TRUE(bank_->open().ok());
    for (int i = 0; i < 200 && !(bank_->status(0).alive && bank_->status(1).alive); ++i) run_ms(5);
    ASSERT_TRUE(bank_->status(0).alive) << bank_->fault_text(0);
    ASSERT_TRUE(bank_->status(1).alive) << bank_->fault_text(1);
  }

  // ... and brings both drives to operation enabled.
  void open_and_enable() {
    open_and_configure();
    ASSERT_TRUE(bank_->enable().ok());
    run_ms(100);
    for (int i = 0; i < 2; ++i) ASSERT_EQ(bank_->status(i).drive, hal::DriveState::kEnabled) << "winch " << i;
  }

  // Sends winch 0 4 m (1 s), quick-stops after 100 ms, waits 400 ms;
  // returns its payout 200 ms after the quick stop.
  double quick_stop_during_a_long_move() {
    EXPECT_TRUE(bank_->set_target_payout(0, bank_->status(0).payout_m + 4.0).ok());
    run_ms(100);
    EXPECT_TRUE(bank_->quick_stop().ok());
    run_ms(200);
    const double stopped_m = bank_->status(0).payout_m;
    run_ms(200);
    return stopped_m;
  }

  hal::TimeUs now_us_ = 0;
  std::unique_ptr<test::FakeCanopenBus> bus_;
  std::unique_ptr<CanopenWinchBank> bank_;
};

TEST_F(CanopenWinchBankTest, ConfiguresStartsAndEnablesDrives) {
  // GIVEN nodes at their profiles' defaults WHEN the bank opens and runs
  start();
  open_and_configure();
  // THEN each node is configured as described and started
  virtual_robot::Cia402Device& d = bus_->drive(0);
  EXPECT_EQ(d.state(), virtual_robot::NodeState::kOperational);
  EXPECT_EQ(d.od().get(0x1600, 0), 2u);
  EXPECT_EQ(d.od().get(0x1600, 2), 0x607A0020u);
  EXPECT_EQ(d.od().get(0x1A00, 2), 0x60640020u);
  EXPECT_EQ(d.od().get(0x1800, 5), 10u);
  EXPECT_EQ(d.od().get(0x1017, 0), 100u);
  EXPECT_EQ(d.od().get(0x1016, 1), (127u << 16) | 500u);
  EXPECT_EQ(d.od().get(0x6007, 0), 3u);
  EXPECT_EQ(d.od().get(0x6081, 0), 20000u);
  EXPECT_EQ(bus_->encoder(0).od().get(0x1A00, 1), 0x60040020u);
  EXPECT_EQ(bus_->encoder(0).state(), virtual_robot::NodeState::kOperational);
  // AND alive with positions, drives still disabled
  hal::WinchStatus s = bank_->status(0);
  EXPECT_GE(s.heartbeat_age_us, 0);
  EXPECT_TRUE(s.position_valid);
  EXPECT_NEAR(s.payout_m, static_cast<double>(bus_->encoder_counts(0)) * kEncoderMPerCount, 1e-12);
  EXPECT_EQ(s.drive, hal::DriveState::kDisabled);
  // WHEN enabled THEN profile position mode is set and every drive is enabled
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(bus_->drive(i).od().get(0x6061, 0), 1u);
    EXPECT_TRUE(bus_->drive(i).operation_enabled());
    EXPECT_EQ(bank_->status(static_cast<int>(i)).drive, hal::DriveState::kEnabled);
  }
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_EQ(bank_->counters().errors, 0u);
}

TEST_F(CanopenWinchBankTest, DriveWithPredefinedMappingMovesOnlyAfterConfiguration) {
  // GIVEN drives with CiA 402's predefined PDOs (RPDO1 = controlword only,
  // TPDO1 = statusword only) WHEN configured, enabled and sent 0.2 m
  start();
  open_and_enable();
  const double start_m = bank_->status(0).payout_m;
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.2).ok());
  // THEN not finished at once (handshake pending) ...
  EXPECT_FALSE(bank_->motion_finished());
  run_ms(20);
  EXPECT_FALSE(bank_->motion_finished());
  // ... and after the move it is, with the encoder at the target: the target
  // position travelled with the controlword in one RPDO
  run_ms(300);
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.2, kEncoderMPerCount);
  EXPECT_NEAR(bus_->drive(0).position_counts(), 1000.0, 0.5);
  // WHEN a second target follows THEN the drive takes it too (new rising edge)
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.1).ok());
  run_ms(300);
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.1, kEncoderMPerCount);
}

TEST_F(CanopenWinchBankTest, CoordinatedMoveStartsAndArrivesTogether) {
  // GIVEN enabled drives
  start();
  open_and_enable();
  const double start0_m = bank_->status(0).payout_m, start1_m = bank_->status(1).payout_m;
  // WHEN winch 0 is sent 0.8 m and winch 1 0.2 m in one coordinated move
  const double targets_m[2] = {start0_m + 0.8, start1_m - 0.2};
  ASSERT_TRUE(bank_->set_target_payouts(targets_m).ok());
  // THEN winch 1 runs at a quarter of winch 0's profile (0x6081/0x6083/0x6084 scaled by |delta|) ...
  run_ms(40);
  EXPECT_EQ(bus_->drive(0).od().get(0x6081, 0), 20000u);
  EXPECT_EQ(bus_->drive(1).od().get(0x6081, 0), 5000u);
  EXPECT_EQ(bus_->drive(1).od().get(0x6083, 0), 50000u);
  // ... so both are the same fraction of the way at every moment, and arrive together
  for (int step = 0; step < 80; ++step) {
    run_ms(5);
    const double done0 = (bank_->status(0).payout_m - start0_m) / 0.8;
    const double done1 = (start1_m - bank_->status(1).payout_m) / 0.2;
    ASSERT_NEAR(done0, done1, 0.03) << "at step " << step;
  }
  run_ms(100);
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, targets_m[0], kEncoderMPerCount);
  EXPECT_NEAR(bank_->status(1).payout_m, targets_m[1], kEncoderMPerCount);
}

TEST_F(CanopenWinchBankTest, RefusedMoveProfileMovesNoWinch) {
  // GIVEN enabled drives, winch 1's drive refusing a new profile acceleration (0x6083 read-only)
  start();
  open_and_enable();
  bus_->drive(1).od().find(0x6083, 0)->access = virtual_robot::Access::kReadOnly;
  const double start0_m = bank_->status(0).payout_m, start1_m = bank_->status(1).payout_m;
  // WHEN winch 0 is sent 0.8 m and winch 1 0.2 m in one coordinated move
  const double targets_m[2] = {start0_m + 0.8, start1_m - 0.2};
  ASSERT_TRUE(bank_->set_target_payouts(targets_m).ok());
  run_ms(400);
  // THEN winch 1 has a fault naming the refusal, and neither winch moved
  EXPECT_TRUE(bank_->status(1).fault);
  EXPECT_NE(bank_->fault_text(1).find("move profile refused, no winch moved: node 2 SDO write 0x6083"),
            std::string::npos)
      << bank_->fault_text(1);
  EXPECT_NEAR(bank_->status(0).payout_m, start0_m, kEncoderMPerCount);
  EXPECT_NEAR(bank_->status(1).payout_m, start1_m, kEncoderMPerCount);
  EXPECT_TRUE(bus_->drive(0).at_rest());
}

// Where a coordinated move's payouts are after a stop: how far the drives'
// stop times spread and how far the payouts left the move's straight line
// (the distance in payout space, as a fraction of the move's length).
struct StopOnTheLine {
  double stop_spread_s = 0.0;
  double off_line_fraction = 0.0;
};

TEST_F(CanopenWinchBankTest, HeartbeatLossStopsEveryWinchAlongTheCommandedLine) {
  // GIVEN enabled drives whose quick stop brakes at 8 m/s^2 (0.5 s from the profile's 4 m/s)
  CanWinchBankConfig config = two_winches();
  config.drive.quick_stop_deceleration_mps2 = 8.0;
  start(config);
  open_and_enable();
  // AND a coordinated move of 8 m on winch 0 and 2 m on winch 1 (a quarter of the speed)
  const double delta_m[2] = {8.0, -2.0};
  const double start_counts[2] = {bus_->drive(0).position_counts(), bus_->drive(1).position_counts()};
  const double targets_m[2] = {bank_->status(0).payout_m + delta_m[0], bank_->status(1).payout_m + delta_m[1]};
  ASSERT_TRUE(bank_->set_target_payouts(targets_m).ok());
  run_ms(300);
  ASSERT_GT(std::abs(bus_->drive(0).demand_counts() - start_counts[0]) * kDriveMPerCount, 0.5);
  // WHEN the master falls silent mid-move and the drives quick-stop on their own
  StopOnTheLine result;
  double stopped_s[2] = {-1.0, -1.0};
  const double length_m = std::hypot(delta_m[0], delta_m[1]);
  for (int t_ms = 0; t_ms < 2000; t_ms += 5) {
    run_ms(5, false);
    double along_m = 0.0, moved_m[2];
    for (int i = 0; i < 2; ++i) {
      moved_m[i] = (bus_->drive(i).position_counts() - start_counts[i]) * kDriveMPerCount;
      along_m += moved_m[i] * delta_m[i] / length_m;
      if (stopped_s[i] < 0.0 && bus_->drive(i).at_rest()) stopped_s[i] = 1e-3 * (t_ms + 5);
    }
    const double off_m = std::hypot(moved_m[0] - along_m * delta_m[0] / length_m, moved_m[1] - along_m * delta_m[1] / length_m);
    result.off_line_fraction = std::max(result.off_line_fraction, off_m / length_m);
  }
  ASSERT_GT(stopped_s[0], 0.0);
  ASSERT_GT(stopped_s[1], 0.0);
  result.stop_spread_s = std::abs(stopped_s[0] - stopped_s[1]);
  std::printf("heartbeat loss mid-move: drives stopped %.3f s and %.3f s after the master's silence (spread %.3f s), "
              "payouts at most %.4f of the move's length off its line\n",
              stopped_s[0], stopped_s[1], result.stop_spread_s, result.off_line_fraction);
  // THEN both stopped short of the targets in quick stop, at the same moment
  // (one 5 ms step), and the payouts never left the line by more than 0.1 %
  // of the move (with one 0x6085 for both: 0.375 s apart and 2 % off)
  EXPECT_EQ(bus_->drive(0).statusword() & 0x006F, 0x0007);
  EXPECT_EQ(bus_->drive(1).statusword() & 0x006F, 0x0007);
  EXPECT_LT(std::abs(bus_->drive(0).position_counts() - start_counts[0]) * kDriveMPerCount, 6.0);
  EXPECT_LE(result.stop_spread_s, 0.005 + 1e-9);
  EXPECT_LT(result.off_line_fraction, 0.001);
  EXPECT_EQ(bus_->drive(1).od().get(0x6085, 0), bus_->drive(0).od().get(0x6085, 0) / 4);
}

TEST_F(CanopenWinchBankTest, DriveLeftInHomingModeIsSwitchedToProfilePosition) {
  // GIVEN drives that power on in homing mode (0x6060 = 6)
  virtual_robot::DriveDefaults homing;
  homing.stored[virtual_robot::object_key(0x6060, 0)] = 6;
  start(two_winches(), homing);
  // WHEN enabled and sent 0.2 m
  open_and_enable();
  EXPECT_EQ(bus_->drive(0).od().get(0x6061, 0), 1u);
  const double start_m = bank_->status(0).payout_m;
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.2).ok());
  run_ms(300);
  // THEN it moved there (in homing, bit 4 would have re-zeroed the drive instead)
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.2, kEncoderMPerCount);
}

TEST_F(CanopenWinchBankTest, DriveThatSwitchesModeLateIsEnabledOnceItShowsTheMode) {
  // GIVEN drives in homing mode that show a new mode in 0x6061 only 150 ms
  // after 0x6060 is written (drives switch asynchronously)
  virtual_robot::DriveDefaults homing;
  homing.stored[virtual_robot::object_key(0x6060, 0)] = 6;
  start(two_winches(), homing);
  bus_->set_mode_switch_delay(150'000);
  // WHEN enabled
  open_and_configure();
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  // THEN not yet enabled and no fault while the drive is switching ...
  EXPECT_NE(bank_->status(0).drive, hal::DriveState::kEnabled);
  EXPECT_FALSE(bank_->status(0).fault) << bank_->fault_text(0);
  run_ms(200);
  // ... and enabled once 0x6061 shows profile position
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(bank_->status(i).drive, hal::DriveState::kEnabled) << "winch " << i << ": " << bank_->fault_text(i);
    EXPECT_FALSE(bank_->status(i).fault) << bank_->fault_text(i);
  }
}

TEST_F(CanopenWinchBankTest, DriveThatNeverShowsTheModeIsRefusedAfterTheTimeout) {
  // GIVEN drives in homing mode that take longer to switch than the bank waits
  CanWinchBankConfig config = two_winches();
  config.mode_switch_timeout_us = 200'000;
  virtual_robot::DriveDefaults homing;
  homing.stored[virtual_robot::object_key(0x6060, 0)] = 6;
  start(config, homing);
  bus_->set_mode_switch_delay(10'000'000);
  // WHEN enabled
  open_and_configure();
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(400);
  // THEN a latched fault names the node, the object and both values; never enabled
  EXPECT_TRUE(bank_->status(0).fault);
  EXPECT_NE(bank_->fault_text(0).find("node 1: 0x6061"), std::string::npos) << bank_->fault_text(0);
  EXPECT_NE(bank_->fault_text(0).find("still 6 200 ms after the mode was written, expected 1"), std::string::npos)
      << bank_->fault_text(0);
  EXPECT_NE(bank_->status(0).drive, hal::DriveState::kEnabled);
}

TEST_F(CanopenWinchBankTest, IdentityMismatchRefusesToEnable) {
  // GIVEN a configuration that expects another vendor than the drives have
  CanWinchBankConfig config = two_winches();
  config.drive.vendor_id = 0x1234;
  start(config);
  ASSERT_TRUE(bank_->open().ok());
  run_ms(200);
  // THEN winch 0 has a fault naming node, object and both values, and is never enabled
  const hal::WinchStatus s = bank_->status(0);
  EXPECT_TRUE(s.fault);
  EXPECT_NE(bank_->fault_text(0).find("node 1: 0x1018:0x01 (vendor id) is 0x0000CD42, expected 0x00001234"),
            std::string::npos)
      << bank_->fault_text(0);
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(200);
  EXPECT_FALSE(bus_->drive(0).operation_enabled());
  EXPECT_NE(bank_->status(0).drive, hal::DriveState::kEnabled);
  // WHEN the operator resets the faults with the cause still there THEN it is tried again and found again
  ASSERT_TRUE(bank_->reset_faults().ok());
  EXPECT_FALSE(bank_->status(0).fault);
  run_ms(200);
  EXPECT_TRUE(bank_->status(0).fault);
  EXPECT_NE(bank_->fault_text(0).find("vendor id"), std::string::npos) << bank_->fault_text(0);
}

TEST_F(CanopenWinchBankTest, RefusedWriteNamesTheAbortCode) {
  // GIVEN a drive description the device refuses (0x6081 of 0 counts/s)
  CanWinchBankConfig config = two_winches();
  config.drive.profile_velocity_mps = 1e-5;  // rounds to 0 counts/s at 2e-4 m per count
  start(config);
  ASSERT_TRUE(bank_->open().ok());
  run_ms(500);
  // THEN the configuration stops there with the device's abort code (its EDS says LowLimit=1)
  EXPECT_TRUE(bank_->status(0).fault);
  EXPECT_NE(bank_->fault_text(0).find(
                "node 1 SDO write 0x6081:0x00: abort 0x06090032 (value of parameter written too low)"),
            std::string::npos)
      << bank_->fault_text(0);
}

TEST_F(CanopenWinchBankTest, PayoutCrossesTheEncoderZero) {
  // GIVEN enabled drives, winch 0 at 0.1 m (encoder count 1000 of its 2^25 range 0x6002)
  start();
  open_and_enable();
  ASSERT_NEAR(bank_->status(0).payout_m, 0.1, 1e-12);
  // WHEN it hauls in to -0.2 m: 0x6004 wraps to 2^25 - 2000
  ASSERT_TRUE(bank_->set_target_payout(0, -0.2).ok());
  run_ms(300);
  ASSERT_EQ(bus_->encoder(0).position_value(), (1u << 25) - 2000u);
  // THEN the payout is -0.2 m, not +3355 m, and the move finished without a fault
  EXPECT_NEAR(bank_->status(0).payout_m, -0.2, 1e-12);
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_FALSE(bank_->status(0).fault);
  // WHEN it pays out again across the zero THEN the count follows
  ASSERT_TRUE(bank_->set_target_payout(0, 0.3).ok());
  run_ms(300);
  EXPECT_NEAR(bank_->status(0).payout_m, 0.3, 1e-12);
}

TEST_F(CanopenWinchBankTest, EncoderJumpIsALatchedFault) {
  // GIVEN enabled drives
  start();
  open_and_enable();
  // WHEN encoder 11 jumps by 100 m between two readings (10 ms apart)
  bus_->winch(0).encoder_offset += 1'000'000;
  run_ms(50);
  // THEN winch 0 has a fault naming the node and the jump, its position is
  // invalid, targets are refused; winch 1 is unaffected
  const hal::WinchStatus s = bank_->status(0);
  EXPECT_TRUE(s.fault);
  EXPECT_FALSE(s.position_valid);
  EXPECT_NE(bank_->fault_text(0).find("node 11: position jumped by 1000000 counts"), std::string::npos)
      << bank_->fault_text(0);
  EXPECT_EQ(bank_->set_target_payout(0, s.payout_m).code(), hal::ErrorCode::kInvalidState);
  EXPECT_FALSE(bank_->status(1).fault);
  // AND the fault stays latched though the readings are steady again
  run_ms(100);
  EXPECT_TRUE(bank_->status(0).fault);
  // WHEN the operator resets the faults THEN the position is read afresh and moves are accepted
  ASSERT_TRUE(bank_->reset_faults().ok());
  run_ms(50);
  EXPECT_FALSE(bank_->status(0).fault);
  EXPECT_TRUE(bank_->status(0).position_valid);
  EXPECT_EQ(bank_->fault_text(0), "");
  EXPECT_TRUE(bank_->set_target_payout(0, bank_->status(0).payout_m + 0.1).ok());
}

TEST_F(CanopenWinchBankTest, MoveLongerThanMaxMoveIsRefused) {
  // GIVEN enabled drives (max_move 250 m by default)
  start();
  open_and_enable();
  const double start_m = bank_->status(0).payout_m;
  // WHEN a target 300 m away is asked for THEN it is refused and nothing moves
  const hal::Status refused = bank_->set_target_payout(0, start_m + 300.0);
  EXPECT_EQ(refused.code(), hal::ErrorCode::kInvalidArgument);
  EXPECT_NE(refused.message().find("exceeds max_move"), std::string::npos) << refused.message();
  run_ms(50);
  EXPECT_NEAR(bus_->drive(0).position_counts(), 0.0, 1e-9);
  EXPECT_TRUE(bank_->motion_finished());
}

TEST_F(CanopenWinchBankTest, LateSetpointAcknowledgementLosesNoTarget) {
  // GIVEN drives that acknowledge a set-point 40 ms late (four PDO cycles)
  virtual_robot::DriveDefaults slow;
  slow.ack_delay_s = 0.040;
  start(two_winches(), slow);
  open_and_enable();
  const double start_m = bank_->status(0).payout_m;
  // WHEN a first target is followed by a second before the first is acknowledged
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.4).ok());
  run_ms(15);
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.1).ok());
  // THEN the motion is finished only at the second target, and the drive is there
  for (int i = 0; i < 200 && !bank_->motion_finished(); ++i) run_ms(5);
  ASSERT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.1, kEncoderMPerCount);
  run_ms(200);
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.1, kEncoderMPerCount);
}

TEST_F(CanopenWinchBankTest, DrivesQuickStopWhenTheMasterHeartbeatStops) {
  // GIVEN winch 0 on a long move (4 m at 4 m/s)
  start();
  open_and_enable();
  const auto master_heartbeats = std::count_if(bus_->received().begin(), bus_->received().end(),
                                               [](const virtual_robot::BusFrame& f) { return f.id == 0x77F; });
  EXPECT_GE(master_heartbeats, 3);
  ASSERT_TRUE(bank_->set_target_payout(0, bank_->status(0).payout_m + 4.0).ok());
  run_ms(200);
  ASSERT_TRUE(bus_->drive(0).operation_enabled());
  // WHEN the master falls silent (its process died)
  const double at_death = bus_->drive(0).position_counts();
  run_ms(1000, false);
  // THEN within the consumer time (500 ms) plus the braking (0.1 s from 4 m/s at 40 m/s^2)
  // the drive is in quick stop at rest, with EMCY 0x8130, and went at most 2.2 m further
  EXPECT_FALSE(bus_->drive(0).operation_enabled());
  EXPECT_EQ(bus_->drive(0).statusword() & 0x006F, 0x0007);  // quick stop active (0x605A = 6)
  EXPECT_TRUE(bus_->drive(0).at_rest());
  const auto& emcy = bus_->drive(0).emergencies();
  EXPECT_NE(std::find(emcy.begin(), emcy.end(), 0x8130), emcy.end());
  const double travelled_m = (bus_->drive(0).position_counts() - at_death) * kDriveMPerCount;
  EXPECT_LT(travelled_m, 4.0 * 0.5 + 4.0 * 4.0 / (2 * 40.0) + 0.05);
  EXPECT_LT(bus_->drive(0).position_counts() * kDriveMPerCount, 3.5);  // it did not finish the move
}

TEST_F(CanopenWinchBankTest, NodeStatusShowsTheDriveInQuickStopAfterAHeartbeatLossUntilTheOperatorResets) {
  // GIVEN enabled drives whose master fell silent for longer than their consumer time
  start();
  open_and_enable();
  run_ms(1000, false);
  // WHEN the master is back and stops the winches, as the daemon does when a run fails
  ASSERT_TRUE(bank_->quick_stop().ok());
  run_ms(300);
  // THEN each winch lists its drive and encoder: NMT operational, the drive in quick
  // stop active with its EMCY 0x8130 (heartbeat), fresh PDOs
  ASSERT_EQ(bank_->node_count(0), 2);
  const hal::NodeStatus drive = bank_->node_status(0, 0);
  EXPECT_STREQ(drive.role, "drive");
  EXPECT_EQ(drive.node_id, 1);
  EXPECT_STREQ(drive.nmt, "operational");
  EXPECT_TRUE(drive.configured);
  EXPECT_STREQ(drive.power_state, "quick stop active");
  EXPECT_EQ(drive.emcy_code, 0x8130);
  EXPECT_STREQ(drive.emcy_text, "life guard or heartbeat error");
  EXPECT_GE(drive.pdo_age_us, 0);
  EXPECT_LE(drive.pdo_age_us, 20'000);
  const hal::NodeStatus encoder = bank_->node_status(0, 1);
  EXPECT_STREQ(encoder.role, "encoder");
  EXPECT_EQ(encoder.node_id, 11);
  EXPECT_STREQ(encoder.power_state, "");
  EXPECT_EQ(encoder.emcy_code, 0);
  // AND the drive stays there: nothing takes it out but the operator
  run_ms(500);
  EXPECT_STREQ(bank_->node_status(0, 0).power_state, "quick stop active");
  // WHEN the operator resets the faults THEN it leaves quick stop and stays disabled
  ASSERT_TRUE(bank_->reset_faults().ok());
  run_ms(150);
  EXPECT_STREQ(bank_->node_status(0, 0).power_state, "ready to switch on");
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kDisabled);
  // AND a node that falls silent says so
  bus_->drive(1).set_silent(true);
  run_ms(700);
  EXPECT_STREQ(bank_->node_status(1, 0).nmt, "silent");
}

TEST_F(CanopenWinchBankTest, FollowingErrorIsAFaultWithItsEmergency) {
  // GIVEN enabled drives, winch 0's motor blocked
  start();
  open_and_enable();
  bus_->drive(0).set_blocked(true);
  // WHEN it is sent 1 m (the demand runs away from the blocked motor)
  ASSERT_TRUE(bank_->set_target_payout(0, bank_->status(0).payout_m + 1.0).ok());
  run_ms(200);
  // THEN the drive faults with EMCY 0x8611 and the message says so
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kFault);
  EXPECT_NE(bank_->fault_text(0).find("EMCY 0x8611 (following error)"), std::string::npos) << bank_->fault_text(0);
  EXPECT_NE(bank_->fault_text(0).find("0x603F = 0x8611 (following error)"), std::string::npos) << bank_->fault_text(0);
  // AND the fault stays: nothing resets it behind the operator's back
  run_ms(500);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kFault);
  // WHEN the operator resets the faults THEN the drive leaves fault but stays disabled
  ASSERT_TRUE(bank_->quick_stop().ok());  // as the daemon does when a run fails
  ASSERT_TRUE(bank_->reset_faults().ok());
  run_ms(150);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kDisabled);
  EXPECT_EQ(bank_->fault_text(0), "");
  // WHEN the operator enables again (motor free) THEN the fault is reset once and the drive enabled
  bus_->drive(0).set_blocked(false);
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(150);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kEnabled);
}

TEST_F(CanopenWinchBankTest, SilentNodeIsDeadAfterHeartbeatTimeout) {
  // GIVEN enabled drives
  start();
  open_and_enable();
  // WHEN node 2 goes silent for less than the 500 ms timeout THEN still alive
  bus_->drive(1).set_silent(true);
  run_ms(300);
  EXPECT_TRUE(bank_->status(1).alive);
  // WHEN silent beyond the timeout THEN dead, finished is false, targets are refused
  run_ms(400);
  const hal::WinchStatus s = bank_->status(1);
  EXPECT_FALSE(s.alive);
  EXPECT_GT(s.heartbeat_age_us, 500'000);
  EXPECT_FALSE(bank_->motion_finished());
  const hal::Status refused = bank_->set_target_payout(1, 1.0);
  EXPECT_EQ(refused.code(), hal::ErrorCode::kInvalidState);
  EXPECT_NE(refused.message().find("node dead"), std::string::npos) << refused.message();
  // AND the other winch is unaffected
  EXPECT_TRUE(bank_->status(0).alive);
}

TEST_F(CanopenWinchBankTest, QuickStopStopsAMovingDrive) {
  // GIVEN winch 0 on a long move (1 s) WHEN quick-stopped
  start();
  open_and_enable();
  const double stopped_m = quick_stop_during_a_long_move();
  // THEN both drives are in quick stop and winch 0 did not move on
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kQuickStop);
  EXPECT_EQ(bank_->status(1).drive, hal::DriveState::kQuickStop);
  EXPECT_DOUBLE_EQ(bank_->status(0).payout_m, stopped_m);
  EXPECT_FALSE(bank_->motion_finished());
  // WHEN enabled again THEN it recovers to operation enabled
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kEnabled);
}

TEST_F(CanopenWinchBankTest, QuickStopEndingSwitchedOffIsHandledToo) {
  // GIVEN drives whose quick stop ends in switch on disabled (0x605A = 2), winch 0 on a long move
  CanWinchBankConfig config = two_winches();
  config.drive.quick_stop_option = 2;
  start(config);
  open_and_enable();
  EXPECT_EQ(bus_->drive(0).od().get(0x605A, 0), 2u);
  // WHEN quick-stopped
  const double stopped_m = quick_stop_during_a_long_move();
  // THEN the drives are off, nothing moves, and the bank does not fight the ending
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kDisabled);
  EXPECT_EQ(bus_->drive(0).statusword() & 0x004F, 0x0040);  // switch on disabled
  EXPECT_DOUBLE_EQ(bank_->status(0).payout_m, stopped_m);
  // WHEN enabled again THEN it comes back
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kEnabled);
}

TEST_F(CanopenWinchBankTest, RebootedDriveIsReconfiguredButNotReEnabled) {
  // GIVEN enabled drives
  start();
  open_and_enable();
  // WHEN drive 1 reboots (boot-up, every object back to its default)
  bus_->drive(0).power_on_reset();
  ASSERT_EQ(bus_->drive(0).od().get(0x1600, 1), 0x60400010u);
  ASSERT_EQ(bus_->drive(0).od().get(0x1600, 0), 1u);
  run_ms(500);
  // THEN the bank configured and started it again but left it disabled
  EXPECT_EQ(bus_->drive(0).state(), virtual_robot::NodeState::kOperational);
  EXPECT_EQ(bus_->drive(0).od().get(0x1600, 2), 0x607A0020u);
  EXPECT_FALSE(bus_->drive(0).operation_enabled());
  EXPECT_TRUE(bank_->status(0).alive);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kDisabled);
  EXPECT_FALSE(bank_->motion_finished());
  // WHEN enable() is called THEN it comes back
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kEnabled);
}

TEST_F(CanopenWinchBankTest, LostPeerIsNotConnected) {
  // GIVEN an open bank WHEN the far end closes
  start();
  open_and_enable();
  bus_.reset();
  // THEN update() reports the lost connection
  const hal::Status s = bank_->update(now_us_ + 5'000);
  EXPECT_EQ(s.code(), hal::ErrorCode::kNotConnected) << s.to_string();
}

// Devices as they come from their makers (docs/fieldbus.md, "Vendor quirks").

TEST_F(CanopenWinchBankTest, EncoderWithTwoTpdosIsConfigured) {
  // GIVEN encoders with only two TPDOs (0x1802/0x1803 and 0x1A02/0x1A03 do
  // not exist: abort 0x06020000) and no RPDO, as Kübler Sendix and SIKO come
  virtual_robot::EncoderDefaults encoder;
  encoder.eds = virtual_robot::shipped_eds("cdpr-virtual-encoder-two-tpdo.eds");
  start(two_winches(), {}, encoder);
  // WHEN the bank configures them THEN they are alive without a fault, TPDO2 switched off
  open_and_configure();
  EXPECT_FALSE(bank_->status(0).fault) << bank_->fault_text(0);
  EXPECT_FALSE(bus_->encoder(0).od().has_index(0x1802));
  EXPECT_NE(bus_->encoder(0).od().get(0x1801, 1) & 0x80000000u, 0u);
  EXPECT_EQ(bus_->encoder(0).od().get(0x1A00, 1), 0x60040020u);
}

TEST_F(CanopenWinchBankTest, DriveKeepingCobIdBit30IsConfigured) {
  // GIVEN drives that hold COB-ID bit 30 at 1 (no RTR) whatever is written, as Lika's manual requires
  virtual_robot::DriveDefaults drive;
  drive.eds = virtual_robot::shipped_eds("cdpr-virtual-drive-rtr-bit30.eds");
  start(two_winches(), drive);
  // WHEN the bank configures them THEN the read back 0x40000201 matches the 0x201 written
  open_and_configure();
  EXPECT_EQ(bus_->drive(0).od().get(0x1400, 1), 0x40000201u);
  EXPECT_EQ(bus_->drive(0).od().get(0x1800, 1), 0x40000181u);
  // AND the drives enable and move on those PDOs
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  const double start_m = bank_->status(0).payout_m;
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.2).ok());
  run_ms(300);
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.2, kEncoderMPerCount);
}

TEST_F(CanopenWinchBankTest, DriveWithoutTransmissionType255GetsType254) {
  // GIVEN drives that refuse transmission type 255 (abort 0x06090030)
  virtual_robot::DriveDefaults drive;
  drive.eds = virtual_robot::shipped_eds("cdpr-virtual-drive-no-type-255.eds");
  start(two_winches(), drive);
  // WHEN the bank configures them THEN their PDOs are event-driven on type 254 and they are alive
  open_and_configure();
  EXPECT_EQ(bus_->drive(0).od().get(0x1800, 2), 254u);
  EXPECT_EQ(bus_->drive(0).od().get(0x1400, 2), 254u);
  EXPECT_FALSE(bank_->status(0).fault) << bank_->fault_text(0);
}

// A drive in rpm: 0.02 m drum, gear 10, 2e-4 m per drive count: 2e-3*pi m
// per motor revolution, so 1 m/s is 60 / (2e-3*pi) = 9549.3 rpm.
constexpr double kMPerMotorRev = 3.14159265358979323846 * 0.02 / 10.0;

virtual_robot::DriveDefaults rpm_drive() {
  virtual_robot::DriveDefaults drive;
  drive.eds = virtual_robot::shipped_eds("cdpr-virtual-drive-rpm.eds");
  drive.counts_per_rev = kMPerMotorRev / kDriveMPerCount;
  drive.stored[virtual_robot::object_key(0x6080, 0)] = 60'000;
  return drive;
}

CanWinchBankConfig rpm_winches() {
  CanWinchBankConfig config = two_winches();
  config.mechanics.drum_diameter_m = 0.02;
  config.mechanics.gear_ratio = 10.0;
  return config;
}

TEST_F(CanopenWinchBankTest, DriveInRpmGetsItsProfileInRpm) {
  // GIVEN drives whose 0x60A9 says rpm (maxon EPOS4's default), with the winch's mechanics configured
  start(rpm_winches(), rpm_drive());
  open_and_configure();
  // THEN 4 m/s is written as 38197 rpm and 40 m/s^2 as 381972 rpm/s (not 20000 counts/s)
  EXPECT_EQ(bus_->drive(0).od().get(0x6081, 0), 38197u);
  EXPECT_EQ(bus_->drive(0).od().get(0x6083, 0), 381972u);
  EXPECT_EQ(bus_->drive(0).od().get(0x6085, 0), 381972u);
  // AND a coordinated move (0.8 m and 0.4 m) scales them in rpm: half way together, on target at the end
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  const double from_m[2] = {bank_->status(0).payout_m, bank_->status(1).payout_m};
  const double to_m[2] = {from_m[0] + 0.8, from_m[1] + 0.4};
  ASSERT_TRUE(bank_->set_target_payouts(to_m).ok());
  run_ms(240);
  EXPECT_EQ(bus_->drive(1).od().get(0x6081, 0), 19099u);
  EXPECT_NEAR((bank_->status(0).payout_m - from_m[0]) / 0.8, (bank_->status(1).payout_m - from_m[1]) / 0.4, 0.03);
  run_ms(400);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(bank_->status(i).payout_m, to_m[i], kEncoderMPerCount) << "winch " << i;
  EXPECT_TRUE(bank_->motion_finished());
}

TEST_F(CanopenWinchBankTest, DriveInRpmWithoutMechanicsIsRefusedNamingTheNode) {
  // GIVEN drives in rpm and no [winches.mechanics]
  start(two_winches(), rpm_drive());
  ASSERT_TRUE(bank_->open().ok());
  run_ms(300);
  // THEN each is a fault naming node and unit, and nothing was written in the wrong unit
  EXPECT_TRUE(bank_->status(0).fault);
  EXPECT_NE(bank_->fault_text(0).find("node 1: 0x60A9 (SI unit velocity) = 0x00B44700 (rpm)"), std::string::npos)
      << bank_->fault_text(0);
  EXPECT_EQ(bus_->drive(0).od().get(0x1800, 5), 0u);  // the configuration stopped after the probe
}

TEST_F(CanopenWinchBankTest, ProfileAboveMaxMotorSpeedIsRefused) {
  // GIVEN drives in rpm whose 0x6080 allows 30000 rpm, and a profile velocity of 4 m/s (38197 rpm)
  virtual_robot::DriveDefaults drive = rpm_drive();
  drive.stored[virtual_robot::object_key(0x6080, 0)] = 30'000;
  start(rpm_winches(), drive);
  ASSERT_TRUE(bank_->open().ok());
  run_ms(300);
  // THEN refused at start, naming node, figure and limit, rather than clamped by the drive
  EXPECT_TRUE(bank_->status(0).fault);
  EXPECT_NE(bank_->fault_text(0).find("node 1: profile_velocity_mps 4.000000 m/s is 38197 rpm, above its max motor "
                                      "speed 0x6080 = 30000 rpm"),
            std::string::npos)
      << bank_->fault_text(0);
}

TEST_F(CanopenWinchBankTest, EveryShippedVirtualDeviceEdsBuildsADeviceTheMasterConfiguresFromThatFile) {
  // GIVEN each virtual device's EDS of systemd/eds, played by the devices
  // (built in) and read by the master from the file, the others plain
  struct Case {
    const char* drive_eds;
    const char* encoder_eds;
  };
  // (and the real devices' files, played from disk: consistent with what the daemon needs, not with the device)
  for (const Case c : {Case{"cdpr-virtual-drive.eds", "cdpr-virtual-encoder.eds"},
                       Case{"cdpr-virtual-drive-rtr-bit30.eds", "cdpr-virtual-encoder.eds"},
                       Case{"cdpr-virtual-drive-no-type-255.eds", "cdpr-virtual-encoder.eds"},
                       Case{"cdpr-virtual-drive-rpm.eds", "cdpr-virtual-encoder.eds"},
                       Case{"cdpr-virtual-drive.eds", "cdpr-virtual-encoder-two-tpdo.eds"},
                       Case{"maxon-epos4.eds", "kuebler-sendix.eds"}}) {
    SCOPED_TRACE(std::string(c.drive_eds) + " + " + c.encoder_eds);
    const bool real = std::string(c.drive_eds) == "maxon-epos4.eds";
    const auto played = [real](const char* name) {
      std::string error;
      return real ? virtual_robot::read_device_eds(std::string(CDPR_SOURCE_DIR) + "/systemd/eds/" + name, error)
                  : virtual_robot::shipped_eds(name);
    };
    virtual_robot::DriveDefaults drive = rpm_drive();
    drive.eds = played(c.drive_eds);
    drive.stored.clear();
    virtual_robot::EncoderDefaults encoder;
    encoder.eds = played(c.encoder_eds);
    ASSERT_EQ(virtual_robot::Cia402Device::check(1, drive), "");
    ASSERT_EQ(virtual_robot::Cia406Device::check(11, encoder), "");
    CanWinchBankConfig config = rpm_winches();
    config.drive.profile_velocity_mps = 1.0;  // 9549 rpm: below the rpm drive's 0x6080 of 10000
    config.drive.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/" + c.drive_eds;
    config.encoder.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/" + c.encoder_eds;
    start(config, drive, encoder);
    ASSERT_EQ(bank_->setup_error(), "");
    // WHEN configured, enabled and moved 0.2 m THEN no fault, and on target
    open_and_enable();
    const double start_m = bank_->status(0).payout_m;
    ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.2).ok());
    run_ms(800);
    EXPECT_TRUE(bank_->motion_finished());
    EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.2, kEncoderMPerCount);
    for (int i = 0; i < 2; ++i) EXPECT_FALSE(bank_->status(i).fault) << bank_->fault_text(i);
  }
}

TEST_F(CanopenWinchBankTest, AWinchWhoseDriveDiffersIsConfiguredFromItsOwnEds) {
  // GIVEN winch 0 with the virtual drive (counts/s) and winch 1 with a drive
  // in rpm, each named by its EDS: [winches.drive] eds and winch 1's drive_eds
  CanWinchBankConfig config = rpm_winches();
  config.drive.profile_velocity_mps = 1.0;  // 9549 rpm, within the rpm drive's 0x6080
  config.drive.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/cdpr-virtual-drive.eds";
  config.winches[1].drive_eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/cdpr-virtual-drive-rpm.eds";
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  bus_ = std::make_unique<test::FakeCanopenBus>(fds[1]);
  bus_->add(1, 11);
  virtual_robot::DriveDefaults rpm = rpm_drive();
  rpm.stored.clear();
  bus_->add(2, 12, rpm);
  const int bank_fd = fds[0];
  bank_ = std::make_unique<CanopenWinchBank>(config, [bank_fd]() -> hal::Result<std::unique_ptr<CanTransport>> {
    return std::unique_ptr<CanTransport>(std::make_unique<FdCanTransport>(bank_fd, "test bank"));
  });
  ASSERT_EQ(bank_->setup_error(), "");
  EXPECT_EQ(bank_->nodes_without_eds(), "encoders 11, 12");
  // WHEN configured THEN each drive has 1 m/s in its own unit: 5000 counts/s and 9549 rpm
  open_and_configure();
  EXPECT_EQ(bus_->drive(0).od().get(0x6081, 0), 5000u);
  EXPECT_EQ(bus_->drive(1).od().get(0x6081, 0), 9549u);
  // AND a coordinated move takes both to their targets
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  const double to_m[2] = {bank_->status(0).payout_m + 0.4, bank_->status(1).payout_m + 0.2};
  ASSERT_TRUE(bank_->set_target_payouts(to_m).ok());
  run_ms(1000);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(bank_->status(i).payout_m, to_m[i], kEncoderMPerCount) << "winch " << i;
}

// The shipped virtual drive's EDS with `sections` added (objects of the factor group).
virtual_robot::DriveDefaults drive_with(const std::string& sections) {
  virtual_robot::DriveDefaults drive;
  drive.eds.text += "\n" + sections;
  return drive;
}

std::string factor_group(const char* index, const char* name, int numerator, int divisor) {
  std::string text = std::string("[") + index + "]\nParameterName=" + name + "\nObjectType=0x8\nSubNumber=3\n\n";
  text += std::string("[") + index + "sub0]\nDataType=0x0005\nAccessType=ro\nDefaultValue=2\n\n";
  text += std::string("[") + index + "sub1]\nDataType=0x0007\nAccessType=rw\nDefaultValue=" + std::to_string(numerator) + "\n\n";
  text += std::string("[") + index + "sub2]\nDataType=0x0007\nAccessType=rw\nDefaultValue=" + std::to_string(divisor) + "\n\n";
  return text;
}

TEST_F(CanopenWinchBankTest, DriveWithAVelocityAndAccelerationFactorGetsItsProfileDividedByThem) {
  // GIVEN drives with a velocity factor 0x6096 = 2/1 and an acceleration factor 0x6097 = 4/1 (no EDS given)
  start(two_winches(), drive_with(factor_group("6096", "Velocity factor", 2, 1) +
                                  factor_group("6097", "Acceleration factor", 4, 1)));
  // WHEN configured THEN 4 m/s (20000 counts/s) is written as 10000 and 40 m/s^2 (200000 counts/s^2) as 50000
  open_and_configure();
  EXPECT_EQ(bus_->drive(0).od().get(0x6081, 0), 10000u);
  EXPECT_EQ(bus_->drive(0).od().get(0x6083, 0), 50000u);
  EXPECT_EQ(bus_->drive(0).od().get(0x6085, 0), 50000u);
  // AND a move of 0.8 m runs the profile the configuration asks: at 4 m/s and 40 m/s^2 it takes 0.3 s
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  const double to_m[2] = {bank_->status(0).payout_m + 0.8, bank_->status(1).payout_m + 0.4};
  ASSERT_TRUE(bank_->set_target_payouts(to_m).ok());
  run_ms(450);  // the profile SDO writes, the set-point handshake and 0.3 s of motion
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(bank_->status(i).payout_m, to_m[i], kEncoderMPerCount) << "winch " << i;
  EXPECT_TRUE(bank_->motion_finished());
}

TEST_F(CanopenWinchBankTest, GearRatioWithRpmIsAStartErrorNamingNodeObjectAndValue) {
  // GIVEN rpm drives whose EDS has a gear ratio 0x6091 of 10 / 1, given to the daemon
  virtual_robot::DriveDefaults drive = rpm_drive();
  drive.eds.text += "\n" + factor_group("6091", "Gear ratio", 10, 1);
  drive.eds.name = ::testing::TempDir() + "geared-rpm.eds";
  {
    std::FILE* f = std::fopen(drive.eds.name.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(drive.eds.text.c_str(), f);
    std::fclose(f);
  }
  CanWinchBankConfig config = rpm_winches();
  config.drive.eds = drive.eds.name;
  start(config, drive);
  // THEN refused at start, before anything is written, naming node, object and value
  EXPECT_EQ(bank_->setup_error(),
            "node 1: 0x6091 (gear ratio) = 10 / 1 with velocities in rpm: whose revolutions those are is the "
            "drive's reading; set it to 1 / 1 and the gear in [winches.mechanics] gear_ratio");
  EXPECT_FALSE(bank_->open().ok());
  // AND without the EDS the same drive is refused when its probe reads 0x6091, as a latched fault
  config.drive.eds.clear();
  start(config, drive);
  ASSERT_TRUE(bank_->open().ok());
  run_ms(300);
  EXPECT_TRUE(bank_->status(0).fault);
  EXPECT_NE(bank_->fault_text(0).find("node 1: 0x6091 (gear ratio) = 10 / 1"), std::string::npos)
      << bank_->fault_text(0);
  EXPECT_EQ(bus_->drive(0).od().get(0x1800, 5), 0u);  // nothing configured after the probe
}

TEST_F(CanopenWinchBankTest, EncoderDescribedByItsEdsIsNotAskedForPdosItLacks) {
  // GIVEN 2-TPDO encoders and their EDS in the configuration
  virtual_robot::EncoderDefaults encoder;
  encoder.eds = virtual_robot::shipped_eds("cdpr-virtual-encoder-two-tpdo.eds");
  CanWinchBankConfig config = two_winches();
  config.encoder.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/kuebler-sendix.eds";
  start(config, {}, encoder);
  EXPECT_EQ(bank_->setup_error(), "");
  EXPECT_EQ(bank_->nodes_without_eds(), "drives 1, 2");
  // WHEN configured THEN alive, and no SDO request ever named 0x1802 or 0x1803
  open_and_configure();
  for (const virtual_robot::BusFrame& f : bus_->received()) {
    if (f.id != 0x600 + 11u) continue;
    const unsigned index = f.data[1] | f.data[2] << 8;
    EXPECT_TRUE(index != 0x1802 && index != 0x1803) << std::hex << index;
  }
}

TEST_F(CanopenWinchBankTest, ConfigurationTheEdsRefusesStopsTheStart) {
  // GIVEN the virtual drive's EDS and a profile velocity its 0x6081 cannot take (0 counts/s)
  CanWinchBankConfig config = two_winches();
  config.drive.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/cdpr-virtual-drive.eds";
  config.drive.profile_velocity_mps = 1e-5;
  start(config);
  // THEN refused before anything is sent, naming node, file, section and key
  EXPECT_NE(bank_->setup_error().find("node 1: " + config.drive.eds +
                                      " [6081] LowLimit=1: profile velocity (0x6081:0x00) 0 (0x0) is out of the "
                                      "device's range"),
            std::string::npos)
      << bank_->setup_error();
  EXPECT_FALSE(bank_->open().ok());
  // AND an EPOS4 (rpm) without [winches.mechanics] is refused the same way
  config = two_winches();
  config.drive.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/maxon-epos4.eds";
  start(config);
  EXPECT_NE(bank_->setup_error().find("node 1: 0x60A9 (SI unit velocity) = 0x00B44700 (rpm)"), std::string::npos)
      << bank_->setup_error();
}

TEST_F(CanopenWinchBankTest, SoftwarePositionLimitsFollowThePayoutRange) {
  // GIVEN a payout range of -1..2 m with a 0.5 m margin; winch 0 at 0.1 m, drive at count 0
  CanWinchBankConfig config = two_winches();
  config.min_payout_m = -1.0;
  config.max_payout_m = 2.0;
  config.position_limit_margin_m = 0.5;
  config.max_move_m = 10.0;
  start(config);
  // WHEN enabled THEN 0x607D is -1.5..2.5 m in drive counts from the present position
  open_and_enable();
  ASSERT_NEAR(bank_->status(0).payout_m, 0.1, 1e-12);
  EXPECT_EQ(bus_->drive(0).od().get_signed(0x607D, 1), -8000);
  EXPECT_EQ(bus_->drive(0).od().get_signed(0x607D, 2), 12000);
  // AND a target beyond it stops at the drive's limit, 2.5 m, whatever the master asks
  ASSERT_TRUE(bank_->set_target_payout(0, 3.5).ok());
  run_ms(1500);
  EXPECT_NEAR(bank_->status(0).payout_m, 2.5, kEncoderMPerCount);
}

TEST_F(CanopenWinchBankTest, ReplacementEncoderCountingTheOtherWayIsRefused) {
  // GIVEN the configuration's code sequence 0 (counting up clockwise) and encoders set to 1
  virtual_robot::EncoderDefaults encoder;
  encoder.stored[virtual_robot::object_key(0x6000, 0)] = 0x0001;
  CanWinchBankConfig config = two_winches();
  config.encoder.code_sequence = 0;
  config.encoder.counts_per_revolution = 4096;
  start(config, {}, encoder);
  ASSERT_TRUE(bank_->open().ok());
  run_ms(300);
  // THEN refused naming node, object and values, rather than paying out backwards
  EXPECT_TRUE(bank_->status(0).fault);
  EXPECT_NE(bank_->fault_text(0).find("node 11: 0x6000:0x00 (code sequence (bit 0)) is 0x0001, expected 0x0000"),
            std::string::npos)
      << bank_->fault_text(0);
}

TEST_F(CanopenWinchBankTest, PayoutPastHalfTheEncoderRangeReadsTheSameAfterARestart) {
  // GIVEN winch 0's encoder at 3/4 of its 2^25-count range (2516.6 m at 0.1 mm per count) and a
  // payout range of 2000..3000 m
  CanWinchBankConfig config = two_winches();
  config.min_payout_m = 2000.0;
  config.max_payout_m = 3000.0;
  start(config);
  bus_->winch(0).encoder_offset = 3 * (1 << 23);
  const double payout_m = 3.0 * (1 << 23) * kEncoderMPerCount;
  // WHEN the bank starts THEN the payout is 2516.6 m, not a whole range (3355.4 m) less
  open_and_configure();
  EXPECT_NEAR(bank_->status(0).payout_m, payout_m, 1e-9);
  // AND after a restart (close, open: the first reading unwrapped afresh) the same
  bank_->close();
  start(config);
  bus_->winch(0).encoder_offset = 3 * (1 << 23);
  open_and_configure();
  EXPECT_NEAR(bank_->status(0).payout_m, payout_m, 1e-9);
}

TEST_F(CanopenWinchBankTest, PayoutPastHalfTheRangeFromItsStartReadsTheSameAfterARestartFromTheKeptPosition) {
  // GIVEN encoders with a 100000-count measuring range (10 m at 0.1 mm), winch 0's at raw 45000,
  // no payout range, and the positions kept in a file
  virtual_robot::EncoderDefaults encoder;
  encoder.stored[virtual_robot::object_key(0x6002, 0)] = 100'000;
  CanWinchBankConfig config = two_winches();
  config.last_positions_path = ::testing::TempDir() + "winch-positions-" + std::to_string(::getpid());
  std::remove(config.last_positions_path.c_str());
  start(config, {}, encoder);
  bus_->winch(0).encoder_offset = 45'000;
  open_and_configure();
  ASSERT_NEAR(bank_->status(0).payout_m, 4.5, 1e-9);
  // WHEN the cable pays out past half the range from zero (to raw 65000, at 8 m/s) and the daemon restarts
  for (int step = 0; step < 50; ++step) {
    bus_->winch(0).encoder_offset += 400;
    run_ms(5);
  }
  ASSERT_NEAR(bank_->status(0).payout_m, 6.5, 1e-9) << bank_->fault_text(0);
  bank_->close();
  start(config, {}, encoder);
  bus_->winch(0).encoder_offset = 65'000;
  open_and_configure();
  // THEN it reads 6.5 m, not a whole range (10 m) less
  EXPECT_NEAR(bank_->status(0).payout_m, 6.5, 1e-9);
  // AND without the kept position (as before) the first reading is taken nearest zero: -3.5 m
  bank_->close();
  config.last_positions_path.clear();
  start(config, {}, encoder);
  bus_->winch(0).encoder_offset = 65'000;
  open_and_configure();
  EXPECT_NEAR(bank_->status(0).payout_m, -3.5, 1e-9);
  std::remove((::testing::TempDir() + "winch-positions-" + std::to_string(::getpid())).c_str());
}

TEST(CanopenWinchBankConfig, RejectsSharedNodeIdsAndZeroScales) {
  CanWinchBankConfig config;
  config.winches = {{1, 11, 1e-4, 1e-4}, {2, 11, 1e-4, 1e-4}};
  EXPECT_NE(validate(config).find("also used by winch 0"), std::string::npos) << validate(config);
  config.winches = {{1, 11, 0.0, 1e-4}};
  EXPECT_NE(validate(config).find("encoder_m_per_count"), std::string::npos);
  config.winches = {{1, 11, 1e-4, 1e-4}};
  EXPECT_EQ(validate(config), "");
  config.master_node_id = 11;
  EXPECT_NE(validate(config).find("master node id 11 also used"), std::string::npos) << validate(config);
  config.master_node_id = 127;
  config.drive.consumer_heartbeat_us = config.master_heartbeat_us;
  EXPECT_NE(validate(config).find("consumer heartbeat"), std::string::npos) << validate(config);
}

TEST(CanConnector, EndpointsSelectTheTransport) {
  // GIVEN connectors for each scheme WHEN called here (no AF_CAN, no socket)
  auto socketcan = make_can_connector("socketcan:cdprtest9")();
  auto unix_missing = make_can_connector("unix:/tmp/cdpr-no-such-dir/can.sock")();
  auto bad = make_can_connector("tcp:1.2.3.4:5")();
  // THEN each fails in its own way
  ASSERT_FALSE(socketcan.ok());
  EXPECT_NE(socketcan.status().message().find("socketcan:cdprtest9"), std::string::npos);
  EXPECT_EQ(unix_missing.status().code(), hal::ErrorCode::kNotConnected);
  EXPECT_EQ(bad.status().code(), hal::ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace cdpr::drivers::can
