// The virtual robot's CANopen devices against CiA 301/402/406 on their own
// (the master's tests use them as the far end; here what a strict device
// refuses and when it sends): SDO aborts, PDO mapping rules, NMT resets,
// TPDO timing, the consumer heartbeat.

#include <gtest/gtest.h>

#include <vector>

#include "virtual-robot/cia402_device.h"
#include "virtual-robot/cia406_device.h"
#include "virtual-robot/object_dictionary_eds.h"

namespace cdpr::virtual_robot {
namespace {

constexpr int kNode = 3;

BusFrame sdo_download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, int size) {
  BusFrame f{0x600 + kNode, 8, {}};
  f.data = {static_cast<std::uint8_t>(0x23 | (4 - size) << 2), static_cast<std::uint8_t>(index),
            static_cast<std::uint8_t>(index >> 8), sub, static_cast<std::uint8_t>(value),
            static_cast<std::uint8_t>(value >> 8), static_cast<std::uint8_t>(value >> 16),
            static_cast<std::uint8_t>(value >> 24)};
  return f;
}

// Sends one SDO download and returns the abort code of the answer (0: confirmed).
std::uint32_t write(CanopenDevice& d, std::uint16_t index, std::uint8_t sub, std::uint32_t value, int size) {
  std::vector<BusFrame> out;
  d.poll(0, out);  // boot-up and anything pending
  out.clear();
  d.on_frame(sdo_download(index, sub, value, size), 0);
  d.poll(0, out);
  for (const BusFrame& f : out) {
    if (f.id != 0x580 + kNode) continue;
    if (f.data[0] == 0x60) return 0;
    if (f.data[0] == 0x80) return f.data[4] | f.data[5] << 8 | f.data[6] << 16 | static_cast<std::uint32_t>(f.data[7]) << 24;
  }
  ADD_FAILURE() << "no SDO answer";
  return 0xFFFFFFFF;
}

TEST(VirtualCanopenDevice, SdoServerRefusesWhatRealDevicesRefuse) {
  Cia402Device d(kNode, DriveDefaults{});
  EXPECT_EQ(write(d, 0x6041, 0, 0x0F, 2), 0x06010002u);  // statusword is read-only
  EXPECT_EQ(write(d, 0x2345, 0, 1, 4), 0x06020000u);     // no such object
  EXPECT_EQ(write(d, 0x1018, 7, 1, 4), 0x06090011u);     // no such sub-index
  EXPECT_EQ(write(d, 0x6081, 0, 1000, 2), 0x06070010u);  // UNSIGNED32 written with 2 bytes
  EXPECT_EQ(write(d, 0x6060, 0, 3, 1), 0x06090030u);     // a mode this drive has not
  EXPECT_EQ(write(d, 0x6060, 0, 1, 1), 0u);
  EXPECT_EQ(d.od().get(0x6061, 0), 1u);                   // the display follows
}

TEST(VirtualCanopenDevice, PdoMappingChangesOnlyWhileThePdoIsInvalid) {
  // GIVEN a drive with its predefined RPDO1 (controlword only, valid)
  Cia402Device d(kNode, DriveDefaults{});
  // THEN its mapping cannot change while valid, nor while sub 0 is not 0
  EXPECT_EQ(write(d, 0x1600, 0, 0, 1), 0x08000022u);
  EXPECT_EQ(write(d, 0x1400, 1, 0x80000200u + kNode, 4), 0u);  // invalidate
  EXPECT_EQ(write(d, 0x1600, 2, 0x607A0020, 4), 0x08000022u);  // sub 0 still 1
  EXPECT_EQ(write(d, 0x1600, 0, 0, 1), 0u);
  EXPECT_EQ(write(d, 0x1600, 2, 0x607A0020, 4), 0u);
  // AND the count is checked against what may be mapped and the 64 bits
  EXPECT_EQ(write(d, 0x1600, 1, 0x60410010, 4), 0u);  // statusword: read-only, not receivable
  EXPECT_EQ(write(d, 0x1600, 0, 2, 1), 0x06040041u);
  EXPECT_EQ(write(d, 0x1600, 1, 0x60400010, 4), 0u);
  EXPECT_EQ(write(d, 0x1600, 3, 0x60810020, 4), 0u);
  EXPECT_EQ(write(d, 0x1600, 4, 0x60830020, 4), 0u);
  EXPECT_EQ(write(d, 0x1600, 0, 4, 1), 0x06040042u);  // 16 + 32 + 32 + 32 bits
  EXPECT_EQ(write(d, 0x1600, 0, 2, 1), 0u);
  // AND a valid COB-ID cannot be changed to another one in one write
  EXPECT_EQ(write(d, 0x1400, 1, 0x200u + kNode, 4), 0u);
  EXPECT_EQ(write(d, 0x1400, 1, 0x300u + kNode, 4), 0x06090030u);
}

TEST(VirtualCanopenDevice, NmtResetBringsTheDefaultsBackWithABootUp) {
  // GIVEN a configured, started drive
  Cia402Device d(kNode, DriveDefaults{});
  ASSERT_EQ(write(d, 0x1017, 0, 100, 2), 0u);
  d.on_frame(BusFrame{0x000, 2, {0x01, kNode}}, 0);
  ASSERT_EQ(d.state(), NodeState::kOperational);
  // WHEN it gets NMT reset node
  d.on_frame(BusFrame{0x000, 2, {0x81, kNode}}, 0);
  std::vector<BusFrame> out;
  d.poll(1000, out);
  // THEN it is pre-operational with its defaults, and says boot-up
  EXPECT_EQ(d.state(), NodeState::kPreOperational);
  EXPECT_EQ(d.od().get(0x1017, 0), 0u);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.front().id, 0x700u + kNode);
  EXPECT_EQ(out.front().data[0], 0x00);
}

TEST(VirtualCanopenDevice, TpdoPerEventTimerAndInhibitTime) {
  // GIVEN an encoder whose TPDO1 has a 20 ms event timer and a 5 ms inhibit time, started
  Cia406Device e(kNode, EncoderDefaults{});
  ASSERT_EQ(write(e, 0x1800, 1, 0x80000180u + kNode, 4), 0u);
  ASSERT_EQ(write(e, 0x1800, 3, 50, 2), 0u);
  ASSERT_EQ(write(e, 0x1800, 5, 20, 2), 0u);
  ASSERT_EQ(write(e, 0x1800, 1, 0x180u + kNode, 4), 0u);
  e.on_frame(BusFrame{0x000, 2, {0x01, kNode}}, 0);
  // WHEN its position changes every millisecond for 100 ms
  int sent = 0;
  std::vector<BusFrame> out;
  for (hal::TimeUs t = 0; t < 100'000; t += 1'000) {
    e.set_position_counts(t / 1'000 - 50);  // crosses zero: wraps at 0x6002
    out.clear();
    e.poll(t, out);
    for (const BusFrame& f : out) sent += f.id == 0x180u + kNode ? 1 : 0;
  }
  // THEN it sent once per inhibit time (20), not every millisecond (100)
  EXPECT_GE(sent, 19);
  EXPECT_LE(sent, 21);
  // AND the position value is UNSIGNED32 modulo the measuring range
  e.set_position_counts(-2);
  EXPECT_EQ(e.position_value(), (1u << 25) - 2u);
  // WHEN the position stands still THEN only the event timer sends (every 20 ms)
  sent = 0;
  for (hal::TimeUs t = 100'000; t < 200'000; t += 1'000) {
    out.clear();
    e.poll(t, out);
    for (const BusFrame& f : out) sent += f.id == 0x180u + kNode ? 1 : 0;
  }
  EXPECT_GE(sent, 5);
  EXPECT_LE(sent, 6);
}

TEST(VirtualCanopenDevice, ConsumerHeartbeatLossQuickStopsPer0x6007) {
  // GIVEN a drive watching node 127's heartbeat (200 ms) that reacts with a quick stop, enabled
  Cia402Device d(kNode, DriveDefaults{});
  ASSERT_EQ(write(d, 0x1016, 1, 127u << 16 | 200u, 4), 0u);
  ASSERT_EQ(write(d, 0x6007, 0, 3, 2), 0u);
  ASSERT_EQ(write(d, 0x6060, 0, 1, 1), 0u);
  d.on_frame(BusFrame{0x000, 2, {0x01, kNode}}, 0);
  for (std::uint16_t cw : {0x06, 0x07, 0x0F}) d.on_frame(BusFrame{0x200 + kNode, 2, {static_cast<std::uint8_t>(cw), 0}}, 0);
  ASSERT_TRUE(d.operation_enabled());
  std::vector<BusFrame> out;
  // WHEN the master's heartbeat comes every 100 ms, then stops at 300 ms
  for (hal::TimeUs t = 0; t <= 300'000; t += 100'000) {
    d.on_frame(BusFrame{0x77F, 1, {0x05}}, t);
    d.poll(t, out);
  }
  d.poll(480'000, out);
  EXPECT_TRUE(d.operation_enabled());  // 180 ms: within the consumer time
  d.poll(520'000, out);
  // THEN after 200 ms it sent EMCY 0x8130 and left operation enabled for quick stop
  EXPECT_FALSE(d.operation_enabled());
  EXPECT_EQ(d.statusword() & 0x006F, 0x0007);
  ASSERT_FALSE(d.emergencies().empty());
  EXPECT_EQ(d.emergencies().back(), 0x8130);
  bool emcy_frame = false;
  for (const BusFrame& f : out) emcy_frame = emcy_frame || (f.id == 0x80u + kNode && f.data[0] == 0x30 && f.data[1] == 0x81);
  EXPECT_TRUE(emcy_frame);
}

// `eds` without the section [name] and its keys.
DeviceEds without_section(DeviceEds eds, const std::string& name) {
  const std::size_t at = eds.text.find("[" + name + "]");
  EXPECT_NE(at, std::string::npos) << name;
  eds.text.erase(at, eds.text.find("\n\n", at) + 2 - at);
  eds.name = "broken.eds";
  return eds;
}

TEST(VirtualCanopenDevice, EdsLackingAnObjectTheDevicePlaysIsRefusedNamingIt) {
  // GIVEN the shipped EDS files, each with one object the device uses taken out
  DriveDefaults drive;
  EXPECT_EQ(Cia402Device::check(kNode, drive), "");
  drive.eds = without_section(drive.eds, "6041");
  EncoderDefaults encoder;
  EXPECT_EQ(Cia406Device::check(kNode, encoder), "");
  encoder.eds = without_section(encoder.eds, "6004");
  DriveDefaults rpm;
  rpm.eds = without_section(shipped_eds("cdpr-virtual-drive-rpm.eds"), "6080");
  DriveDefaults no_event_timer;
  no_event_timer.eds = without_section(no_event_timer.eds, "1800sub5");
  // WHEN checked THEN refused, naming file and object, before any device plays it
  EXPECT_EQ(Cia402Device::check(kNode, drive), "broken.eds: no object 0x6041:00 (statusword), which the drive plays");
  EXPECT_EQ(Cia406Device::check(kNode, encoder), "broken.eds: no object 0x6004:00, which the encoder plays");
  EXPECT_EQ(Cia402Device::check(kNode, rpm),
            "broken.eds: no object 0x6080:00 (max motor speed), which a drive in rpm plays");
  EXPECT_EQ(Cia402Device::check(kNode, no_event_timer), "broken.eds: no object 0x1800:05");
}

TEST(VirtualCanopenDevice, ObjectsComeFromTheEdsWithNodeIdRangeAndStoredValues) {
  // GIVEN a drive from the no-type-255 EDS, stored to power on in homing
  DriveDefaults drive;
  drive.eds = shipped_eds("cdpr-virtual-drive-no-type-255.eds");
  drive.stored[object_key(0x6060, 0)] = 6;
  Cia402Device d(kNode, drive);
  // THEN $NODEID is its own id, the stored mode is in effect, 255 is above the range and 254 taken
  EXPECT_EQ(d.od().get(0x1800, 1), 0x180u + kNode);
  EXPECT_EQ(d.od().get(0x6061, 0), 6u);
  EXPECT_EQ(write(d, 0x1800, 2, 255, 1), 0x06090031u);
  EXPECT_EQ(write(d, 0x1800, 2, 254, 1), 0u);
  // AND an NMT reset node brings back the stored mode, not the EDS's DefaultValue
  EXPECT_EQ(write(d, 0x6060, 0, 1, 1), 0u);
  d.on_frame(BusFrame{0x000, 2, {0x81, kNode}}, 0);
  EXPECT_EQ(d.od().get(0x6060, 0), 6u);
  // AND a drive from the rtr-bit30 EDS keeps bit 30 whatever is written
  drive.eds = shipped_eds("cdpr-virtual-drive-rtr-bit30.eds");
  Cia402Device rtr(kNode, drive);
  EXPECT_EQ(write(rtr, 0x1400, 1, 0x80000000u | (0x200u + kNode), 4), 0u);
  EXPECT_EQ(rtr.od().get(0x1400, 1), 0xC0000000u | (0x200u + kNode));
}

}  // namespace
}  // namespace cdpr::virtual_robot

namespace cdpr::virtual_robot {
namespace {

TEST(VirtualCanopenDevice, RecordsTheLongestGapBetweenTheMastersHeartbeats) {
  // GIVEN a drive watching node 127's heartbeat (500 ms)
  Cia402Device d(kNode, DriveDefaults{});
  ASSERT_EQ(write(d, 0x1016, 1, 127u << 16 | 500u, 4), 0u);
  EXPECT_EQ(d.longest_consumer_gap_us(), 0);
  // WHEN the heartbeats come at 0, 100, 380 and 480 ms, and another node's at 700 ms
  for (const hal::TimeUs t : {0, 100'000, 380'000, 480'000}) d.on_frame(BusFrame{0x77F, 1, {0x05}}, t);
  d.on_frame(BusFrame{0x77E, 1, {0x05}}, 700'000);
  // THEN the longest gap is the master's 280 ms (what the small-computer measurement reports)
  EXPECT_EQ(d.longest_consumer_gap_us(), 280'000);
}

}  // namespace
}  // namespace cdpr::virtual_robot
