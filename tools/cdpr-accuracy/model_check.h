#pragma once
// The paper's Table I model check: the fitting model (catenary, Eq. 1-4, and
// the reference-cable statics, Eq. 5-11) fed with the simulator's true pose,
// anchors and reference force, against the simulator's own equilibrium.

#include <cstdint>
#include <string>

#include "sim/presets.h"

namespace cdpr::accuracy {

struct ModelCheck {
  int poses = 0;
  double mean_length_error_pct = 0.0;  // MPE-L over all cables
  double max_length_error_pct = 0.0;
  double mean_force_error_pct = 0.0;   // MPE-F over the cables whose force the statics predict
  double max_force_error_pct = 0.0;
  double min_length_m = 0.0, max_length_m = 0.0, min_force_n = 0.0, max_force_n = 0.0;
  std::string error;  // non-empty when the simulation or the model failed
};

ModelCheck model_check(sim::Preset preset, int poses, std::uint64_t seed);

}  // namespace cdpr::accuracy
