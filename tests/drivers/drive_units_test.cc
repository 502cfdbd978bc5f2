// The conversion of payout figures into a CiA 402 drive's own units (0x60A9).

#include "drivers/can/drive_units.h"

#include <gtest/gtest.h>

namespace cdpr::drivers::can {
namespace {

constexpr double kMPerCount = 1e-5;
constexpr double kMPerRev = 0.05;

DriveUnits units_or_fail(std::optional<std::uint32_t> code, double m_per_rev = kMPerRev) {
  std::string why;
  const std::optional<DriveUnits> units = drive_units(code, kMPerCount, m_per_rev, why);
  EXPECT_TRUE(units) << why;
  return units.value_or(DriveUnits{});
}

TEST(DriveUnits, WithoutObjectTheDriveCountsIncrementsPerSecond) {
  // GIVEN a drive without 0x60A9 THEN 2 m/s is 200000 counts/s
  EXPECT_EQ(drive_value(units_or_fail(std::nullopt), 2.0), 200'000u);
}

TEST(DriveUnits, RpmAndItsPowersOfTen) {
  // GIVEN 0.05 m per motor revolution: 1 m/s is 20 rev/s = 1200 rpm
  EXPECT_EQ(drive_value(units_or_fail(0x00B44700), 1.0), 1200u);
  EXPECT_EQ(units_or_fail(0x00B44700).name, "rpm");
  // 0.001 rpm (0xFD prefix, Synapticon's finest)
  EXPECT_EQ(drive_value(units_or_fail(0xFDB44700), 1.0), 1'200'000u);
  // rev/s
  EXPECT_EQ(drive_value(units_or_fail(0x00B40300), 1.0), 20u);
  // 0.1 increments/s
  EXPECT_EQ(drive_value(units_or_fail(0xFFB50300), 1.0), 1'000'000u);
}

TEST(DriveUnits, RevolutionsWithoutMechanicsOrUnknownUnitsAreRefused) {
  std::string why;
  // GIVEN rpm but no drum configured THEN refused, saying what to set
  EXPECT_FALSE(drive_units(0x00B44700, kMPerCount, 0.0, why));
  EXPECT_NE(why.find("set [winches.mechanics]"), std::string::npos) << why;
  // GIVEN metres per second (0x01 = metre) THEN refused naming the code
  EXPECT_FALSE(drive_units(0x00010300, kMPerCount, kMPerRev, why));
  EXPECT_NE(why.find("0x00010300"), std::string::npos) << why;
}

TEST(DriveUnits, TooSmallAFigureRoundsToZeroForTheDriveToRefuse) {
  EXPECT_EQ(drive_value(units_or_fail(0x00B44700), 1e-4), 0u);
}

}  // namespace
}  // namespace cdpr::drivers::can
