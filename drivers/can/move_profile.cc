#include "drivers/can/move_profile.h"

#include <algorithm>
#include <cmath>

namespace cdpr::drivers::can {

MoveProfileCounts scaled_move_profile(const DriveDescription& drive, double share, const DriveUnits& units) {
  const auto scaled = [&](double per_s) { return std::max<std::uint32_t>(1, drive_value(units, share * per_s)); };
  const auto scaled2 = [&](double per_s2) {
    return std::max<std::uint32_t>(1, drive_acceleration(units, share * per_s2));
  };
  MoveProfileCounts p;
  p.velocity = scaled(drive.profile_velocity_mps);
  p.acceleration = scaled2(drive.profile_acceleration_mps2);
  p.deceleration = scaled2(drive.profile_deceleration_mps2);
  p.quick_stop_deceleration = scaled2(drive.quick_stop_deceleration_mps2);
  return p;
}

MoveProfileCounts scaled_move_profile(const DriveDescription& drive, double share, double m_per_count) {
  return scaled_move_profile(drive, share, DriveUnits{1.0 / std::abs(m_per_count), "counts/s"});
}

}  // namespace cdpr::drivers::can
