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
// (0x6083, 0x6084, 0x6085) count the velocity unit per second, unless the
// drive has 0x60AA (SI unit acceleration, coded as 0x60A9 with the time
// byte read as per second squared: 0xPPB50300 increments/s^2, 0xPPB40300
// rev/s^2).
//
// The factor group: a velocity factor 0x6096 (numerator / divisor) and an
// acceleration factor 0x6097 turn the values written into the drive's
// internal ones (internal = written x numerator / divisor), so the daemon
// writes its figures times divisor / numerator. The gear ratio 0x6091
// (motor / shaft revolutions) must be 1:1 when the drive counts
// revolutions: whose revolutions its rpm are (motor or shaft) is the
// vendor's reading, so the gear goes in [winches.mechanics]. Positions
// (0x6091 with increments, the feed constant 0x6092) need nothing: the
// configuration's drive_m_per_count is per position unit as 0x6064 shows
// it. Pure functions, no I/O.

#include <cstdint>
#include <optional>
#include <string>

namespace cdpr::drivers::can {

struct DriveUnits {
  double per_mps = 0.0;   // 0x6081 and 0x6080 units per m/s of payout
  std::string name;       // "counts/s", "rpm", "0.1 rpm", ... for messages
  double per_mps2 = 0.0;  // 0x6083/0x6084/0x6085 units per m/s^2; 0: per_mps (the velocity unit per second)
};

// The drive's unit objects as it (or its EDS) gives them; nullopt: it has not that object.
struct DriveUnitObjects {
  std::optional<std::uint32_t> si_unit_velocity;                   // 0x60A9
  std::optional<std::uint32_t> si_unit_acceleration;               // 0x60AA
  std::optional<std::uint32_t> gear_motor_revs, gear_shaft_revs;   // 0x6091:01, :02
  std::optional<std::uint32_t> velocity_numerator, velocity_divisor;          // 0x6096:01, :02
  std::optional<std::uint32_t> acceleration_numerator, acceleration_divisor;  // 0x6097:01, :02
};

// The drive's units from its 0x60A9 (nullopt: the drive has none) with
// `m_per_count` payout per position count and `m_per_motor_rev` payout per
// motor revolution (0: not configured). Nullopt with `why` set when the
// daemon cannot convert into them.
std::optional<DriveUnits> drive_units(std::optional<std::uint32_t> si_unit_velocity, double m_per_count,
                                      double m_per_motor_rev, std::string& why);
// The same from all the unit objects; `why` names the object and value the daemon cannot honour.
std::optional<DriveUnits> drive_units(const DriveUnitObjects& objects, double m_per_count, double m_per_motor_rev,
                                      std::string& why);

// `si` [m/s or m/s^2] in the drive's units, rounded (0 for a figure below
// half a unit: the drive refuses it, and says so).
std::uint32_t drive_value(const DriveUnits& units, double si);
// `si` [m/s^2] in the drive's acceleration units, rounded likewise.
std::uint32_t drive_acceleration(const DriveUnits& units, double si);

}  // namespace cdpr::drivers::can
