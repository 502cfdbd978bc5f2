#pragma once
// The CiA 402 profile of one winch for one coordinated move, in its drive's
// units (drive_units.h: counts/s, rpm, ...): the drive description's profile velocity, acceleration and
// deceleration (0x6081, 0x6083, 0x6084) and its quick-stop deceleration
// (0x6085), all scaled by share = |delta_i| / max |delta|.
//
// Why the quick-stop deceleration too: every winch then runs a copy of the
// longest winch's trapezoid scaled by its share, so whenever the drives
// brake together (halt on 0x6084; quick stop or a lost master heartbeat on
// 0x6085, 0x605A = 6) each needs the same time, v_i / d_i = v / d, to
// stop, and the payouts stay on the straight line between the two
// waypoints. One 0x6085 for all would stop the short winches first and
// leave the line (a slack or overloaded cable).
// Pure; no I/O.

#include <cstdint>

#include "drivers/can/device_configuration.h"
#include "drivers/can/drive_units.h"

namespace cdpr::drivers::can {

struct MoveProfileCounts {
  std::uint32_t velocity = 1;                 // 0x6081 [the drive's velocity unit]
  std::uint32_t acceleration = 1;             // 0x6083 [that unit per second]
  std::uint32_t deceleration = 1;             // 0x6084
  std::uint32_t quick_stop_deceleration = 1;  // 0x6085
};

// share in [0, 1]. Each value is at least 1: CiA 402 drives refuse 0.
MoveProfileCounts scaled_move_profile(const DriveDescription& drive, double share, const DriveUnits& units);
// The same for a drive at the standard's default, position counts per
// second; m_per_count != 0 (its sign is ignored).
MoveProfileCounts scaled_move_profile(const DriveDescription& drive, double share, double m_per_count);

}  // namespace cdpr::drivers::can
