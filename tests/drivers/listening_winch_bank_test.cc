// The listen-only winch bank (watch mode): it hears the nodes' heartbeats
// and TPDOs on a bus another master runs, and never sends a frame.

#include <sys/socket.h>
#include <unistd.h>

#include <memory>

#include <gtest/gtest.h>

#include "drivers/can/canopen.h"
#include "drivers/can/cia402.h"
#include "drivers/can/fd_can_transport.h"
#include "drivers/can/listening_winch_bank.h"

namespace cdpr::drivers::can {
namespace {

CanWinchBankConfig two_winches(int encoder_node_of_second) {
  CanWinchBankConfig config;
  config.winches = {{1, 11, 1e-5, 1e-5}, {2, encoder_node_of_second, 1e-5, 1e-5}};
  config.heartbeat_timeout_us = 300'000;
  return config;
}

class ListeningWinchBankTest : public ::testing::Test {
 protected:
  void start(const CanWinchBankConfig& config, const ListenLayout& layout = {}) {
    int fds[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
    bus_ = std::make_unique<FdCanTransport>(fds[1], "test bus");
    const int bank_fd = fds[0];
    bank_ = std::make_unique<ListeningWinchBank>(config, layout, [bank_fd]() -> hal::Result<std::unique_ptr<CanTransport>> {
      return std::unique_ptr<CanTransport>(std::make_unique<FdCanTransport>(bank_fd, "test listener"));
    });
    ASSERT_TRUE(bank_->open().ok());
  }
  void put(const CanFrame& frame) { ASSERT_TRUE(bus_->send(frame).ok()); }
  // Frames the bank sent onto the bus (there must be none).
  int frames_from_bank() {
    int n = 0;
    CanFrame frame;
    for (;;) {
      const hal::Result<bool> got = bus_->receive(frame, 0);
      if (!got.ok() || !got.value()) return n;
      ++n;
    }
  }

  std::unique_ptr<FdCanTransport> bus_;
  std::unique_ptr<ListeningWinchBank> bank_;
};

TEST_F(ListeningWinchBankTest, HearsHeartbeatsAndTpdosOfTheDefaultLayoutAndSendsNothing) {
  // GIVEN winch 0 with an encoder, winch 1 counting on its drive alone
  start(two_winches(0));
  const std::uint16_t enabled = cia402::statusword_of(cia402::PowerState::kOperationEnabled) | cia402::kSwTargetReached;
  // WHEN the nodes publish as the robot's controller configured them, with
  // the controller's own RPDOs, SDOs and SYNC on the bus too
  for (int node : {1, 2, 11}) put(make_heartbeat(node, NmtState::kOperational));
  put(make_drive_txpdo(1, enabled, 123));
  put(make_encoder_tpdo(11, 5'000'000));
  put(make_drive_txpdo(2, enabled, 2'500'000));
  put(make_drive_rxpdo(1, 0x000F, 77));
  put(CanFrame{0x601, 8, {0x22, 0x81, 0x60, 0, 1, 2, 3, 4}});
  put(CanFrame{0x080, 0, {}});
  ASSERT_TRUE(bank_->update(1'000).ok());

  // THEN each winch is alive with its payout, the drives enabled
  const hal::WinchStatus w0 = bank_->status(0), w1 = bank_->status(1);
  EXPECT_TRUE(w0.alive);
  EXPECT_TRUE(w0.position_valid);
  EXPECT_NEAR(w0.payout_m, 50.0, 1e-9);  // the encoder's, not the drive's
  EXPECT_EQ(w0.drive, hal::DriveState::kEnabled);
  EXPECT_TRUE(w1.alive);
  EXPECT_NEAR(w1.payout_m, 25.0, 1e-9);
  EXPECT_EQ(bank_->counters().frames_ignored, 3u);
  EXPECT_STREQ(bank_->node_status(0, 1).nmt, "operational");

  // AND every command is refused without a frame on the bus
  const double targets[2] = {1.0, 2.0};
  for (const hal::Status& s : {bank_->enable(), bank_->set_target_payouts(targets), bank_->halt(),
                               bank_->quick_stop(), bank_->disable()}) {
    EXPECT_EQ(s.code(), hal::ErrorCode::kInvalidState);
  }
  ASSERT_TRUE(bank_->update(400'000).ok());
  EXPECT_FALSE(bank_->status(0).alive);  // silent past the heartbeat timeout
  bank_->close();
  EXPECT_EQ(frames_from_bank(), 0);
  EXPECT_EQ(bank_->counters().frames_tx, 0u);
}

TEST_F(ListeningWinchBankTest, FindsValuesWhereTheLayoutSays) {
  // GIVEN a controller that maps the encoder's position at byte 2 of 0x280 + node
  ListenLayout layout;
  layout.encoder_tpdo_base = 0x280;
  layout.encoder_position_byte = 2;
  start(two_winches(12), layout);
  // WHEN its TPDO comes, and one at the default COB-ID
  put(CanFrame{0x280 + 12, 6, {0xAA, 0xBB, 0x40, 0x42, 0x0F, 0x00}});
  put(make_encoder_tpdo(11, 1));
  ASSERT_TRUE(bank_->update(1'000).ok());
  // THEN the first is winch 1's payout and the second is no one's
  EXPECT_NEAR(bank_->status(1).payout_m, 1e-5 * 0x0F4240, 1e-9);
  EXPECT_FALSE(bank_->status(0).position_valid);
  EXPECT_EQ(bank_->counters().frames_ignored, 1u);
}

TEST(ListenLayout, RefusesOffsetsBeyondTheFrame) {
  ListenLayout layout;
  EXPECT_EQ(validate(layout), "");
  layout.encoder_position_byte = 5;
  EXPECT_NE(validate(layout).find("encoder_position_byte 5"), std::string::npos);
  layout = {};
  layout.drive_position_byte = -1;
  EXPECT_EQ(validate(layout), "");
}

}  // namespace
}  // namespace cdpr::drivers::can
