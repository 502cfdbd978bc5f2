// Loopback: the CANopen winch bank against fake CiA 402/406 nodes on the far
// end of a real Unix stream socket pair, time stepped by the test.

#include "drivers/can/canopen_winch_bank.h"

#include <sys/socket.h>
#include <unistd.h>

#include <memory>

#include <gtest/gtest.h>

#include "drivers/can/fd_can_transport.h"
#include "fake_canopen_bus.h"

namespace cdpr::drivers::can {
namespace {

constexpr double kEncoderMPerCount = 1e-4;  // 0.1 mm per encoder count
constexpr double kDriveMPerCount = 2e-4;    // fake gearing: 2 encoder counts per drive count

class CanopenWinchBankTest : public ::testing::Test {
 protected:
  void SetUp() override {
    int fds[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
    bus_ = std::make_unique<test::FakeCanopenBus>(fds[1]);
    bus_->add(1, 11);
    bus_->add(2, 12);
    CanWinchBankConfig config;
    config.winches = {{1, 11, kEncoderMPerCount, kDriveMPerCount}, {2, 12, kEncoderMPerCount, kDriveMPerCount}};
    config.heartbeat_timeout_us = 500'000;
    const int bank_fd = fds[0];
    bank_ = std::make_unique<CanopenWinchBank>(config, [bank_fd]() -> hal::Result<std::unique_ptr<CanTransport>> {
      return std::unique_ptr<CanTransport>(std::make_unique<FdCanTransport>(bank_fd, "test bank"));
    });
  }

  // Steps the fake nodes and the bank every 5 ms for `duration_ms`.
  void run_ms(int duration_ms) {
    for (int t = 0; t < duration_ms; t += 5) {
      now_us_ += 5'000;
      bus_->step(now_us_);
      ASSERT_TRUE(bank_->update(now_us_).ok());
    }
  }

  // Opens the bank and brings both drives to operation enabled.
  void open_and_enable() {
    ASSERT_TRUE(bank_->open().ok());
    run_ms(50);
    ASSERT_TRUE(bank_->enable().ok());
    run_ms(100);
    for (int i = 0; i < 2; ++i) ASSERT_EQ(bank_->status(i).drive, hal::DriveState::kEnabled) << "winch " << i;
  }

  hal::TimeUs now_us_ = 0;
  std::unique_ptr<test::FakeCanopenBus> bus_;
  std::unique_ptr<CanopenWinchBank> bank_;
};

TEST_F(CanopenWinchBankTest, StartsNodesAndEnablesDrives) {
  // GIVEN booting nodes WHEN the bank opens and runs a while
  ASSERT_TRUE(bank_->open().ok());
  run_ms(50);
  // THEN the nodes were started (NMT), are alive, positions arrive, drives still disabled
  for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(bus_->drive(i).nmt, NmtState::kOperational);
  hal::WinchStatus s = bank_->status(0);
  EXPECT_TRUE(s.alive);
  EXPECT_GE(s.heartbeat_age_us, 0);
  EXPECT_TRUE(s.position_valid);
  EXPECT_NEAR(s.payout_m, bus_->encoder_counts(bus_->drive(0)) * kEncoderMPerCount, 1e-12);
  EXPECT_EQ(s.drive, hal::DriveState::kDisabled);
  // WHEN enabled THEN every drive walks to operation enabled and holds still
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(bus_->drive(i).power, cia402::PowerState::kOperationEnabled);
    EXPECT_EQ(bank_->status(static_cast<int>(i)).drive, hal::DriveState::kEnabled);
  }
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_GT(bank_->counters().frames_rx, 0u);
  EXPECT_GT(bank_->counters().frames_tx, 0u);
  EXPECT_EQ(bank_->counters().errors, 0u);
}

TEST_F(CanopenWinchBankTest, MovesToTargetPayoutAndReportsFinished) {
  // GIVEN enabled drives
  open_and_enable();
  const double start_m = bank_->status(0).payout_m;
  // WHEN winch 0 is sent 0.2 m further (1000 drive counts at 20000 counts/s: 50 ms)
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.2).ok());
  // THEN it is not finished at once (handshake pending) ...
  EXPECT_FALSE(bank_->motion_finished());
  run_ms(20);
  EXPECT_FALSE(bank_->motion_finished());
  // ... and after the move it is, with the encoder at the target
  run_ms(200);
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.2, kEncoderMPerCount);
  EXPECT_NEAR(bank_->status(0).target_payout_m, start_m + 0.2, 1e-12);
  EXPECT_EQ(bus_->drive(0).target_counts, 1000);
  // WHEN a second target follows THEN the drive takes it too (new rising edge)
  ASSERT_TRUE(bank_->set_target_payout(0, start_m + 0.1).ok());
  run_ms(200);
  EXPECT_TRUE(bank_->motion_finished());
  EXPECT_NEAR(bank_->status(0).payout_m, start_m + 0.1, kEncoderMPerCount);
}

TEST_F(CanopenWinchBankTest, SilentNodeIsDeadAfterHeartbeatTimeout) {
  // GIVEN enabled drives
  open_and_enable();
  // WHEN node 2 goes silent for less than the 500 ms timeout THEN still alive
  bus_->drive(1).silent = true;
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
  // GIVEN winch 0 on a long move (1 s)
  open_and_enable();
  ASSERT_TRUE(bank_->set_target_payout(0, bank_->status(0).payout_m + 4.0).ok());
  run_ms(100);
  // WHEN quick-stopped
  ASSERT_TRUE(bank_->quick_stop().ok());
  run_ms(20);
  const double stopped_m = bank_->status(0).payout_m;
  run_ms(200);
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

TEST_F(CanopenWinchBankTest, EnableResetsAFault) {
  // GIVEN a drive that reports a fault
  ASSERT_TRUE(bank_->open().ok());
  run_ms(50);
  bus_->drive(0).power = cia402::PowerState::kFault;
  run_ms(20);
  ASSERT_EQ(bank_->status(0).drive, hal::DriveState::kFault);
  // WHEN enabled THEN the fault is reset and the drive enabled
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kEnabled);
}

TEST_F(CanopenWinchBankTest, RebootedDriveIsStartedButNotReEnabled) {
  // GIVEN enabled drives
  open_and_enable();
  // WHEN drive 1 reboots (boot-up, pre-operational, switch on disabled)
  test::FakeCanopenBus::Drive& d = bus_->drive(0);
  d.booted_us = -1;
  d.nmt = NmtState::kPreOperational;
  d.power = cia402::PowerState::kSwitchOnDisabled;
  run_ms(300);
  // THEN the bank started it again (NMT) but left it disabled, and motion is not finished
  EXPECT_EQ(d.nmt, NmtState::kOperational);
  EXPECT_EQ(d.power, cia402::PowerState::kSwitchOnDisabled);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kDisabled);
  EXPECT_FALSE(bank_->motion_finished());
  // WHEN enable() is called THEN it comes back
  ASSERT_TRUE(bank_->enable().ok());
  run_ms(100);
  EXPECT_EQ(bank_->status(0).drive, hal::DriveState::kEnabled);
}

TEST_F(CanopenWinchBankTest, LostPeerIsNotConnected) {
  // GIVEN an open bank WHEN the far end closes
  open_and_enable();
  bus_.reset();
  // THEN update() reports the lost connection
  const hal::Status s = bank_->update(now_us_ + 5'000);
  EXPECT_EQ(s.code(), hal::ErrorCode::kNotConnected) << s.to_string();
}

TEST(CanopenWinchBankConfig, RejectsSharedNodeIdsAndZeroScales) {
  CanWinchBankConfig config;
  config.winches = {{1, 11, 1e-4, 1e-4}, {2, 11, 1e-4, 1e-4}};
  EXPECT_NE(validate(config).find("also used by winch 0"), std::string::npos) << validate(config);
  config.winches = {{1, 11, 0.0, 1e-4}};
  EXPECT_NE(validate(config).find("encoder_m_per_count"), std::string::npos);
  config.winches = {{1, 11, 1e-4, 1e-4}};
  EXPECT_EQ(validate(config), "");
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
