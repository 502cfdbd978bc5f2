#pragma once
// The sensor groups whose noise a fit can measure against robot.toml's
// sigmas, and one group's measurement (solver/calibration/noise_components.h).

#include <string_view>

namespace cdpr {

enum class NoiseGroup : int { kEncoder, kLoadCell, kPosition, kOrientation, kHeight };
inline constexpr int kNoiseGroupCount = 5;

// "encoder", "load_cell", "position", "orientation", "height".
std::string_view noise_group_name(NoiseGroup group);
// In words for a report: "encoder noise", ..., "height consistency".
std::string_view noise_group_description(NoiseGroup group);

struct NoiseComponent {
  NoiseGroup group = NoiseGroup::kEncoder;
  int rows = 0;              // residual rows in the group
  double chi_square = 0.0;   // sum of whitened residuals squared (robot.toml's sigma)
  double redundancy = 0.0;   // sum of 1 - h_ii
  double scale = 1.0;        // sqrt(chi_square / redundancy): implied sigma / stated sigma
  double p_high = 1.0;       // P(chi-square(redundancy) > chi_square): noisier than stated
  double likelihood_gain = 0.0;  // -2 log L drop of a refit with the group's sigma scaled
};

}  // namespace cdpr
