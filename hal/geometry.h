#pragma once
// Plain geometric value types for hal/ (hal sees no Eigen: only hal headers).
// Frames are named where these are used: a position is "<point>_<frame>"
// ("platform_world"), a rotation "<to>_R_<from>" ("world_R_platform").

namespace cdpr::hal {

struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

// Unit quaternion w + xi + yj + zk (Hamilton convention, as Eigen and
// samples.csv). Identity by default.
struct Quaternion {
  double w = 1.0;
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

}  // namespace cdpr::hal
