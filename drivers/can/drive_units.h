#pragma once
// The units a CiA 402 drive counts its profile in, and the conversion of
// the daemon's payout figures [m/s, m/s^2] into them.
//
// CiA 402-2 object 0x60A9 (SI unit velocity, UNSIGNED32): bits 31-24 a
// signed power of ten, 23-16 the unit (0xB5 increments, 0xB4 revolutions),
// 15-8 the time (0x03 second, 0x47 minute). Without 0x60A9 the drive is at
// the standard's default: position increments per second (factor group at
// 1). Drives that speak rpm (maxon EPOS4, Nanotec, Synapticon: 0x00B44700)
// need the winch's metres per motor revolution. Acceleration objects
// (0x6083, 0x6084, 0x6085) count the velocity unit per second, so the
// factor per m/s^2 equals the factor per m/s. Pure functions, no I/O.

#include <cstdint>
#include <optional>
#include <string>

namespace cdpr::drivers::can {

struct DriveUnits {
  double per_mps = 0.0;   // 0x6081 and 0x6080 units per m/s of payout (and 0x6083.. per m/s^2)
  std::string name;       // "counts/s", "rpm", "0.1 rpm", ... for messages
};

// The drive's units from its 0x60A9 (nullopt: the drive has none) with
// `m_per_count` payout per position count and `m_per_motor_rev` payout per
// motor revolution (0: not configured). Nullopt with `why` set when the
// daemon cannot convert into them.
std::optional<DriveUnits> drive_units(std::optional<std::uint32_t> si_unit_velocity, double m_per_count,
                                      double m_per_motor_rev, std::string& why);

// `si` [m/s or m/s^2] in the drive's units, rounded (0 for a figure below
// half a unit: the drive refuses it, and says so).
std::uint32_t drive_value(const DriveUnits& units, double si);

}  // namespace cdpr::drivers::can
