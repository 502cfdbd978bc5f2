// EDS files (CiA 306) read with libinih, and the master's configuration
// fitted to them: the shipped files of systemd/eds, and small ones made here.

#include "drivers/can/eds.h"

#include <gtest/gtest.h>

#include "drivers/can/device_configuration.h"

namespace cdpr::drivers::can {
namespace {

std::string shipped(const char* name) { return std::string(CDPR_SOURCE_DIR) + "/systemd/eds/" + name; }

Eds load_or_fail(const std::string& path) {
  std::string error;
  std::optional<Eds> eds = Eds::load(path, error);
  EXPECT_TRUE(eds) << error;
  return eds ? std::move(*eds) : Eds{};
}

bool touches(const std::vector<SdoStep>& steps, std::uint16_t index) {
  for (const SdoStep& s : steps) {
    if (s.index == index) return true;
  }
  return false;
}

TEST(Eds, ShippedFilesParseWithTheirPdoCounts) {
  const Eds epos4 = load_or_fail(shipped("maxon-epos4.eds"));
  EXPECT_EQ(epos4.rpdo_count(), 4);
  EXPECT_EQ(epos4.tpdo_count(), 4);
  ASSERT_NE(epos4.find(0x60A9, 0), nullptr);
  EXPECT_EQ(epos4.find(0x60A9, 0)->default_value, 0x00B44700);
  const Eds sendix = load_or_fail(shipped("kuebler-sendix.eds"));
  EXPECT_EQ(sendix.rpdo_count(), 0);
  EXPECT_EQ(sendix.tpdo_count(), 2);
  EXPECT_EQ(sendix.find(0x1800, 2)->high, 254);
  EXPECT_EQ(load_or_fail(shipped("cdpr-virtual-drive.eds")).tpdo_count(), 4);
  EXPECT_EQ(load_or_fail(shipped("cdpr-virtual-encoder.eds")).rpdo_count(), 4);
  EXPECT_EQ(load_or_fail(shipped("cdpr-virtual-encoder-two-tpdo.eds")).tpdo_count(), 2);
}

TEST(Eds, UnusedPdosTheDeviceLacksAreLeftOut) {
  // GIVEN the encoder configuration and a 2-TPDO encoder's EDS
  std::vector<SdoStep> steps = encoder_configuration(11, EncoderDescription{});
  ASSERT_TRUE(touches(steps, 0x1802));
  // WHEN fitted THEN TPDO 3 and 4 are never asked for, TPDO 2 still switched off
  EXPECT_EQ(fit_to_eds(load_or_fail(shipped("kuebler-sendix.eds")), steps), "");
  EXPECT_FALSE(touches(steps, 0x1802));
  EXPECT_FALSE(touches(steps, 0x1803));
  EXPECT_TRUE(touches(steps, 0x1801));
}

constexpr const char* kSmallDrive = R"([1800sub1]
AccessType=rw
DataType=0x0007
DefaultValue=$NODEID+0x40000180
[1800sub2]
AccessType=rw
DataType=0x0005
HighLimit=254
[6065]
AccessType=ro
DataType=0x0007
[6081]
AccessType=rw
DataType=0x0007
LowLimit=1
HighLimit=5000
)";

std::vector<SdoStep> one(SdoStep step) { return {step}; }

TEST(Eds, ReadOnlyObjectIsRefusedWithFileSectionAndKey) {
  std::string error;
  const std::optional<Eds> eds = Eds::parse(kSmallDrive, "small.eds", error);
  ASSERT_TRUE(eds) << error;
  std::vector<SdoStep> steps = one({SdoStep::Kind::kWriteVerify, 0x6065, 0, 4, 100, "following error window"});
  EXPECT_EQ(fit_to_eds(*eds, steps),
            "small.eds [6065] AccessType=ro: following error window (0x6065:0x00) is written by the daemon");
}

TEST(Eds, ValueOutOfRangeIsRefusedWithTheLimit) {
  std::string error;
  const std::optional<Eds> eds = Eds::parse(kSmallDrive, "small.eds", error);
  ASSERT_TRUE(eds) << error;
  std::vector<SdoStep> steps = one({SdoStep::Kind::kWriteVerify, 0x6081, 0, 4, 20000, "profile velocity"});
  EXPECT_EQ(fit_to_eds(*eds, steps),
            "small.eds [6081] HighLimit=5000: profile velocity (0x6081:0x00) 20000 (0x4E20) is out of the device's range");
}

TEST(Eds, MissingNeededObjectIsRefusedAndOptionalOneLeftOut) {
  std::string error;
  const std::optional<Eds> eds = Eds::parse(kSmallDrive, "small.eds", error);
  ASSERT_TRUE(eds) << error;
  std::vector<SdoStep> steps = one({SdoStep::Kind::kWriteVerify, 0x6085, 0, 4, 1, "quick stop deceleration"});
  EXPECT_EQ(fit_to_eds(*eds, steps), "small.eds: no object 0x6085:0x00 (quick stop deceleration), which the daemon needs");
  SdoStep optional{SdoStep::Kind::kRead, 0x60A9, 0, 4, 0, "SI unit velocity"};
  optional.optional = true;
  steps = one(optional);
  EXPECT_EQ(fit_to_eds(*eds, steps), "");
  EXPECT_TRUE(steps.empty());
}

TEST(Eds, TransmissionType254WhereTheRangeStopsShortOf255AndBit30AsTheDefaultHasIt) {
  // GIVEN the drive's TPDO1 as the master configures it
  std::string error;
  const std::optional<Eds> eds = Eds::parse(kSmallDrive, "small.eds", error);
  ASSERT_TRUE(eds) << error;
  std::vector<SdoStep> steps;
  for (const SdoStep& s : drive_configuration(1, 127, 1e-5, DriveUnits{1e5, "counts/s"}, DriveDescription{})) {
    if (s.index == 0x1800 && (s.subindex == 1 || s.subindex == 2)) steps.push_back(s);
  }
  // WHEN fitted THEN type 254 is written at once, and the COB-ID with bit 30 as the EDS's default
  ASSERT_EQ(fit_to_eds(*eds, steps), "");
  for (const SdoStep& s : steps) {
    if (s.subindex == 2) {
      EXPECT_EQ(s.value, 254u);
    } else {
      EXPECT_NE(s.value & 0x40000000u, 0u) << std::hex << s.value;
    }
  }
}

TEST(Eds, SyntaxErrorNamesTheLine) {
  std::string error;
  EXPECT_FALSE(Eds::parse("[6081]\nAccessType=rw\nnot a key line\n", "bad.eds", error));
  EXPECT_EQ(error, "bad.eds:3: not INI syntax");
  EXPECT_FALSE(Eds::parse("[6081]\nHighLimit=fast\n", "bad.eds", error));
  EXPECT_EQ(error, "bad.eds:2: [6081] HighLimit=fast: not a number");
  EXPECT_FALSE(Eds::load("/nonexistent/x.eds", error));
  EXPECT_EQ(error, "/nonexistent/x.eds: cannot read the EDS file");
}

}  // namespace
}  // namespace cdpr::drivers::can
