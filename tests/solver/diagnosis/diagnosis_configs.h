#pragma once
// Simulated data sets the model-discrepancy tests share: the large robot of
// the paper, 45 poses (3-fold cross-validation), nominal anchors 2 m off, the
// default sensor noise (as tools/diagnose-acceptance.sh "large").

#include <cstdint>

#include "sim/dataset.h"

namespace cdpr::test {

inline sim::DatasetConfig large_robot_45_poses(std::uint64_t seed) {
  sim::DatasetConfig c;
  c.pose_count = 45;
  c.seed = seed;
  c.anchor_perturbation_m = 2.0;
  return c;
}

}  // namespace cdpr::test
