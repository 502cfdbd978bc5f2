#pragma once
// The independent random streams of one simulated data set (sim/rng.h):
// each purpose draws from its own stream of the seed, so changing one part
// of a simulation (an effect, the noise scale) leaves the other numbers as
// they were, and cases with the same seed stay paired.

#include <cstdint>

namespace cdpr::sim {

inline constexpr std::uint64_t kStreamEncoderOffsets = 1;
inline constexpr std::uint64_t kStreamAnchorPerturbation = 2;
inline constexpr std::uint64_t kStreamWaypointShift = 3;
inline constexpr std::uint64_t kStreamWaypointYaw = 4;  // index: candidate
inline constexpr std::uint64_t kStreamSensorNoise = 5;  // index: candidate
inline constexpr std::uint64_t kStreamEncoderOutliers = 6;
inline constexpr std::uint64_t kStreamForceSpikes = 7;
// The rows measured at positions given after the regular ones (DatasetConfig::extra_positions).
inline constexpr std::uint64_t kStreamExtraPoseNoise = 20;  // index: extra position

}  // namespace cdpr::sim
