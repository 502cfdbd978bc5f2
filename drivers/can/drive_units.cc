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

std::uint32_t drive_value(const DriveUnits& units, double si) {
  const double value = std::round(std::abs(si) * units.per_mps);
  return static_cast<std::uint32_t>(std::min(value, 4294967295.0));
}

}  // namespace cdpr::drivers::can
