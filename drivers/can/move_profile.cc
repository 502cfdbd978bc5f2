#include "drivers/can/move_profile.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cdpr::drivers::can {

MoveProfileCounts scaled_move_profile(const DriveDescription& drive, double share, double m_per_count) {
  const double per_count = 1.0 / std::abs(m_per_count);
  const auto scaled = [&](double per_s) {
    const double counts = std::round(share * per_s * per_count);
    return static_cast<std::uint32_t>(std::clamp(counts, 1.0, double{std::numeric_limits<std::uint32_t>::max()}));
  };
  MoveProfileCounts p;
  p.velocity = scaled(drive.profile_velocity_mps);
  p.acceleration = scaled(drive.profile_acceleration_mps2);
  p.deceleration = scaled(drive.profile_deceleration_mps2);
  p.quick_stop_deceleration = scaled(drive.quick_stop_deceleration_mps2);
  return p;
}

}  // namespace cdpr::drivers::can
