#pragma once
// Candidate static poses for a data set, well spread over the workspace:
// a Halton sequence (bases 2, 3, 5) over the preset's box, shifted by a
// random offset modulo 1 (Cranley-Patterson rotation) so each seed gives a
// different but equally even set; yaw ~ N(0, sigma) per candidate. The
// caller skips candidates without a taut equilibrium.

#include <cstdint>

#include <Eigen/Core>

#include "sim/presets.h"

namespace cdpr::sim {

struct Waypoint {
  int candidate = 0;  // index in the sequence (also names the noise stream of its sample)
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  double yaw_rad = 0.0;
};

class WaypointSequence {
 public:
  WaypointSequence(const PresetSpec& spec, std::uint64_t seed);
  Waypoint next();

 private:
  Eigen::Vector3d low_, size_;
  double yaw_sigma_rad_;
  std::uint64_t seed_;
  Eigen::Vector3d shift_;
  int index_ = 0;
};

}  // namespace cdpr::sim
