#include "sim/waypoints.h"

#include <cmath>

#include "sim/rng.h"
#include "sim/stream_purpose.h"

namespace cdpr::sim {
namespace {

// Radical inverse of `index` in `base`: the index-th Halton coordinate.
double radical_inverse(int index, int base) {
  double result = 0.0;
  double digit_scale = 1.0 / base;
  for (int i = index; i > 0; i /= base) {
    result += (i % base) * digit_scale;
    digit_scale /= base;
  }
  return result;
}

}  // namespace

WaypointSequence::WaypointSequence(const PresetSpec& spec, std::uint64_t seed)
    : low_(spec.workspace_min),
      size_(spec.workspace_max - spec.workspace_min),
      yaw_sigma_rad_(spec.yaw_sigma_rad),
      seed_(seed) {
  Rng rng = Rng::stream(seed, kStreamWaypointShift);
  shift_ = Eigen::Vector3d(rng.uniform(), rng.uniform(), rng.uniform());
}

Waypoint WaypointSequence::next() {
  const int index = index_++;
  const int bases[3] = {2, 3, 5};
  Waypoint w;
  w.candidate = index;
  for (int k = 0; k < 3; ++k) {
    const double u = radical_inverse(index + 1, bases[k]) + shift_(k);
    w.position_world(k) = low_(k) + size_(k) * (u - std::floor(u));
  }
  Rng yaw_rng = Rng::stream(seed_, kStreamWaypointYaw, static_cast<std::uint64_t>(index));
  w.yaw_rad = yaw_sigma_rad_ * yaw_rng.normal();
  return w;
}

}  // namespace cdpr::sim
