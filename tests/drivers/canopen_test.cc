// CANopen frames and the CiA 402 power state machine against the standard's
// tables, written out by hand (not through the code under test).

#include "drivers/can/canopen.h"

#include <gtest/gtest.h>

#include "drivers/can/cia402.h"

namespace cdpr::drivers::can {
namespace {

TEST(CanopenFrames, DriveRxPdoIsControlwordThenTargetLittleEndian) {
  // GIVEN controlword 0x003F and target -2 for node 5
  const CanFrame frame = make_drive_rxpdo(5, 0x003F, -2);
  // THEN COB-ID 0x205 and bytes 3F 00 FE FF FF FF
  EXPECT_EQ(frame.id, 0x205u);
  ASSERT_EQ(frame.len, 6);
  const std::uint8_t expected[6] = {0x3F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(frame.data[i], expected[i]) << "byte " << i;
  const auto parsed = parse_drive_rxpdo(frame);
  ASSERT_TRUE(parsed);
  EXPECT_EQ(parsed->target_counts, -2);
}

TEST(CanopenFrames, EncoderTpdoAndHeartbeatAndNmt) {
  CanFrame tpdo;
  tpdo.id = 0x18B;
  tpdo.len = 4;
  tpdo.data = {0x78, 0x56, 0x34, 0x12, 0, 0, 0, 0};
  EXPECT_EQ(node_of(tpdo, kTpdo1Base), 11);
  EXPECT_EQ(parse_encoder_tpdo(tpdo), 0x12345678);
  EXPECT_FALSE(node_of(tpdo, kHeartbeatBase));

  CanFrame heartbeat;
  heartbeat.id = 0x70B;
  heartbeat.len = 1;
  heartbeat.data[0] = 0x7F;
  EXPECT_EQ(parse_heartbeat(heartbeat), NmtState::kPreOperational);
  heartbeat.data[0] = 0x33;  // no such state
  EXPECT_FALSE(parse_heartbeat(heartbeat));

  const CanFrame nmt = make_nmt(NmtCommand::kStart, 11);
  EXPECT_EQ(nmt.id, 0u);
  EXPECT_EQ(nmt.data[0], 0x01);
  EXPECT_EQ(nmt.data[1], 11);
}

TEST(Cia402, DecodesTheStateCodingTable) {
  using cia402::PowerState;
  EXPECT_EQ(cia402::decode_power_state(0x0250), PowerState::kSwitchOnDisabled);  // with remote+voltage bits
  EXPECT_EQ(cia402::decode_power_state(0x0231), PowerState::kReadyToSwitchOn);
  EXPECT_EQ(cia402::decode_power_state(0x0233), PowerState::kSwitchedOn);
  EXPECT_EQ(cia402::decode_power_state(0x0637), PowerState::kOperationEnabled);  // + target reached
  EXPECT_EQ(cia402::decode_power_state(0x0217), PowerState::kQuickStopActive);
  EXPECT_EQ(cia402::decode_power_state(0x021F), PowerState::kFaultReactionActive);
  EXPECT_EQ(cia402::decode_power_state(0x0218), PowerState::kFault);
}

TEST(Cia402, DeviceWalksToOperationEnabledAndBack) {
  using cia402::PowerState;
  PowerState s = PowerState::kSwitchOnDisabled;
  s = cia402::next_power_state(s, 0x0006, 0x0000);
  EXPECT_EQ(s, PowerState::kReadyToSwitchOn);
  s = cia402::next_power_state(s, 0x0007, 0x0006);
  EXPECT_EQ(s, PowerState::kSwitchedOn);
  s = cia402::next_power_state(s, 0x000F, 0x0007);
  EXPECT_EQ(s, PowerState::kOperationEnabled);
  s = cia402::next_power_state(s, 0x0002, 0x000F);
  EXPECT_EQ(s, PowerState::kQuickStopActive);
  s = cia402::next_power_state(s, 0x0000, 0x0002);
  EXPECT_EQ(s, PowerState::kSwitchOnDisabled);
  // Fault reset needs a rising edge of bit 7.
  EXPECT_EQ(cia402::next_power_state(PowerState::kFault, 0x0080, 0x0080), PowerState::kFault);
  EXPECT_EQ(cia402::next_power_state(PowerState::kFault, 0x0080, 0x0000), PowerState::kSwitchOnDisabled);
  // Round trip: each state's statusword decodes to itself.
  for (PowerState p : {PowerState::kNotReadyToSwitchOn, PowerState::kSwitchOnDisabled, PowerState::kReadyToSwitchOn,
                       PowerState::kSwitchedOn, PowerState::kOperationEnabled, PowerState::kQuickStopActive,
                       PowerState::kFaultReactionActive, PowerState::kFault}) {
    EXPECT_EQ(cia402::decode_power_state(cia402::statusword_of(p)), p) << cia402::to_string(p);
  }
}

}  // namespace
}  // namespace cdpr::drivers::can
