#include "drivers/can/drive_units.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cdpr::drivers::can {
namespace {

constexpr std::uint8_t kUnitIncrements = 0xB5;
constexpr std::uint8_t kUnitRevolutions = 0xB4;
constexpr std::uint8_t kTimeSecond = 0x03;
constexpr std::uint8_t kTimeMinute = 0x47;

std::string unit_code_hex(std::uint32_t code) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%08X", static_cast<unsigned>(code));
  return text;
}

std::string prefixed(int exponent, const char* unit) {
  if (exponent == 0) return unit;
  char text[48];
  std::snprintf(text, sizeof(text), "1e%d %s", exponent, unit);
  return text;
}

}  // namespace

std::optional<DriveUnits> drive_units(std::optional<std::uint32_t> si_unit_velocity, double m_per_count,
                                      double m_per_motor_rev, std::string& why) {
  const double counts_per_m = 1.0 / std::abs(m_per_count);
  if (!si_unit_velocity) return DriveUnits{counts_per_m, "counts/s"};
  const std::uint32_t code = *si_unit_velocity;
  const int exponent = static_cast<std::int8_t>(code >> 24);
  const auto unit = static_cast<std::uint8_t>(code >> 16), time = static_cast<std::uint8_t>(code >> 8);
  const double scale = std::pow(10.0, -exponent);  // drive units per (unit / time)
  char hex[16];
  std::snprintf(hex, sizeof(hex), "0x%08X", static_cast<unsigned>(code));
  if (exponent < -6 || exponent > 6 || (code & 0xFF) != 0) {
    why = std::string("0x60A9 (SI unit velocity) = ") + hex + " is not a CiA 402 unit code";
    return std::nullopt;
  }
  if (unit == kUnitIncrements && time == kTimeSecond) return DriveUnits{counts_per_m * scale, prefixed(exponent, "counts/s")};
  if (unit == kUnitRevolutions && (time == kTimeMinute || time == kTimeSecond)) {
    const bool per_minute = time == kTimeMinute;
    if (!(m_per_motor_rev > 0.0)) {
      why = std::string("0x60A9 (SI unit velocity) = ") + hex + " (" + (per_minute ? "rpm" : "rev/s") +
            "): the drive counts motor revolutions; set [winches.mechanics] drum_diameter_m and gear_ratio";
      return std::nullopt;
    }
    const double rev_per_m = 1.0 / m_per_motor_rev;
    return DriveUnits{rev_per_m * (per_minute ? 60.0 : 1.0) * scale, prefixed(exponent, per_minute ? "rpm" : "rev/s")};
  }
  why = std::string("0x60A9 (SI unit velocity) = ") + hex +
        ": a unit the daemon does not convert to (it knows increments/s, rev/min and rev/s)";
  return std::nullopt;
}

std::optional<DriveUnits> drive_units(const DriveUnitObjects& objects, double m_per_count, double m_per_motor_rev,
                                      std::string& why) {
  std::optional<DriveUnits> units = drive_units(objects.si_unit_velocity, m_per_count, m_per_motor_rev, why);
  if (!units) return std::nullopt;
  const bool revolutions = objects.si_unit_velocity && static_cast<std::uint8_t>(*objects.si_unit_velocity >> 16) == kUnitRevolutions;
  units->per_mps2 = units->per_mps;  // the velocity unit per second
  if (objects.si_unit_acceleration) {
    const std::uint32_t code = *objects.si_unit_acceleration;
    const int exponent = static_cast<std::int8_t>(code >> 24);
    const auto unit = static_cast<std::uint8_t>(code >> 16), time = static_cast<std::uint8_t>(code >> 8);
    const double scale = std::pow(10.0, -exponent);
    if (exponent < -6 || exponent > 6 || (code & 0xFF) != 0 || time != kTimeSecond ||
        (unit != kUnitIncrements && unit != kUnitRevolutions) || (unit == kUnitRevolutions && !(m_per_motor_rev > 0.0))) {
      why = "0x60AA (SI unit acceleration) = " + unit_code_hex(code) +
            ": a unit the daemon does not convert to (it knows increments/s^2 and rev/s^2, the latter with "
            "[winches.mechanics])";
      return std::nullopt;
    }
    units->per_mps2 = (unit == kUnitIncrements ? 1.0 / std::abs(m_per_count) : 1.0 / m_per_motor_rev) * scale;
  }
  const auto ratio = [&why](const char* object, std::optional<std::uint32_t> numerator,
                            std::optional<std::uint32_t> divisor) -> std::optional<double> {
    if (!numerator && !divisor) return 1.0;
    if (!numerator || !divisor || *numerator == 0 || *divisor == 0) {
      why = std::string(object) + " = " + (numerator ? std::to_string(*numerator) : "?") + " / " +
            (divisor ? std::to_string(*divisor) : "?") + ": not a factor the daemon can honour";
      return std::nullopt;
    }
    return static_cast<double>(*numerator) / static_cast<double>(*divisor);
  };
  const std::optional<double> gear = ratio("0x6091 (gear ratio)", objects.gear_motor_revs, objects.gear_shaft_revs);
  const std::optional<double> velocity =
      gear ? ratio("0x6096 (velocity factor)", objects.velocity_numerator, objects.velocity_divisor) : std::nullopt;
  const std::optional<double> acceleration =
      velocity ? ratio("0x6097 (acceleration factor)", objects.acceleration_numerator, objects.acceleration_divisor)
               : std::nullopt;
  if (!acceleration) return std::nullopt;
  if (revolutions && *gear != 1.0) {
    why = "0x6091 (gear ratio) = " + std::to_string(*objects.gear_motor_revs) + " / " +
          std::to_string(*objects.gear_shaft_revs) + " with velocities in " + units->name +
          ": whose revolutions those are is the drive's reading; set it to 1 / 1 and the gear in "
          "[winches.mechanics] gear_ratio";
    return std::nullopt;
  }
  units->per_mps /= *velocity;
  units->per_mps2 /= *acceleration;
  return units;
}

std::uint32_t drive_value(const DriveUnits& units, double si) {
  const double value = std::round(std::abs(si) * units.per_mps);
  return static_cast<std::uint32_t>(std::min(value, 4294967295.0));
}

std::uint32_t drive_acceleration(const DriveUnits& units, double si) {
  const double value = std::round(std::abs(si) * (units.per_mps2 > 0.0 ? units.per_mps2 : units.per_mps));
  return static_cast<std::uint32_t>(std::min(value, 4294967295.0));
}

}  // namespace cdpr::drivers::can
