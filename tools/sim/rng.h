#pragma once
// Reproducible random numbers for simulated data sets: the same seed gives
// the same numbers on every platform and standard library (std::normal_
// distribution and friends are implementation-defined, so they are not used).
// xoshiro256** seeded through SplitMix64; normals by Box-Muller.

#include <array>
#include <cstdint>

namespace cdpr::sim {

class Rng {
 public:
  explicit Rng(std::uint64_t seed);
  // An independent stream for one purpose (waypoints, offsets, noise of pose
  // k, ...), so that changing one part of a simulation leaves the others'
  // numbers unchanged.
  static Rng stream(std::uint64_t seed, std::uint64_t purpose, std::uint64_t index = 0);

  std::uint64_t next();
  double uniform();                          // [0, 1)
  double uniform(double low, double high);   // [low, high)
  double normal();                           // N(0, 1)

 private:
  std::array<std::uint64_t, 4> state_{};
  double spare_normal_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace cdpr::sim
