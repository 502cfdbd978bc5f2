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
TEST(DriveUnits, TheFactorGroupIsHonouredAndAnAccelerationUnitOfItsOwnConverted) {
  // GIVEN a drive in increments (1e-4 m per count) with a velocity factor 2/1 and an acceleration factor 1/4
  DriveUnitObjects objects;
  objects.velocity_numerator = 2;
  objects.velocity_divisor = 1;
  objects.acceleration_numerator = 1;
  objects.acceleration_divisor = 4;
  std::string why;
  std::optional<DriveUnits> units = drive_units(objects, 1e-4, 0.0, why);
  ASSERT_TRUE(units) << why;
  // THEN 1 m/s (10000 counts/s inside the drive) is written as 5000, 1 m/s^2 as 40000
  EXPECT_EQ(drive_value(*units, 1.0), 5000u);
  EXPECT_EQ(drive_acceleration(*units, 1.0), 40000u);
  // AND an rpm drive with 0x60AA = 0xFFB40300 (0.1 rev/s^2) and 2e-3*pi m per motor revolution: 1 m/s^2 is 1591.5
  DriveUnitObjects rpm;
  rpm.si_unit_velocity = 0x00B44700;
  rpm.si_unit_acceleration = 0xFFB40300;
  units = drive_units(rpm, 1e-4, 2e-3 * 3.14159265358979323846, why);
  ASSERT_TRUE(units) << why;
  EXPECT_EQ(drive_value(*units, 1.0), 9549u);
  EXPECT_EQ(drive_acceleration(*units, 1.0), 1592u);
}

TEST(DriveUnits, AFactorTheDaemonCannotHonourIsRefusedNamingObjectAndValue) {
  std::string why;
  // GIVEN a drive in rpm whose gear ratio 0x6091 is 10 / 1: whose rpm are those?
  DriveUnitObjects geared;
  geared.si_unit_velocity = 0x00B44700;
  geared.gear_motor_revs = 10;
  geared.gear_shaft_revs = 1;
  EXPECT_FALSE(drive_units(geared, 1e-4, 0.01, why));
  EXPECT_EQ(why,
            "0x6091 (gear ratio) = 10 / 1 with velocities in rpm: whose revolutions those are is the drive's reading; "
            "set it to 1 / 1 and the gear in [winches.mechanics] gear_ratio");
  // AND a zero divisor, a lone numerator, an acceleration unit per minute
  DriveUnitObjects zero;
  zero.velocity_numerator = 1;
  zero.velocity_divisor = 0;
  EXPECT_FALSE(drive_units(zero, 1e-4, 0.0, why));
  EXPECT_EQ(why, "0x6096 (velocity factor) = 1 / 0: not a factor the daemon can honour");
  DriveUnitObjects lone;
  lone.acceleration_numerator = 3;
  EXPECT_FALSE(drive_units(lone, 1e-4, 0.0, why));
  EXPECT_EQ(why, "0x6097 (acceleration factor) = 3 / ?: not a factor the daemon can honour");
  DriveUnitObjects per_minute;
  per_minute.si_unit_acceleration = 0x00B54700;
  EXPECT_FALSE(drive_units(per_minute, 1e-4, 0.0, why));
  EXPECT_NE(why.find("0x60AA (SI unit acceleration) = 0x00B54700"), std::string::npos) << why;
  // AND a gear in increments is the drive's own business (positions are per 0x6064 unit)
  DriveUnitObjects increments;
  increments.gear_motor_revs = 10;
  increments.gear_shaft_revs = 1;
  EXPECT_TRUE(drive_units(increments, 1e-4, 0.0, why)) << why;
}

}  // namespace cdpr::drivers::can
