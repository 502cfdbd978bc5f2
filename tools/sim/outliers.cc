#include "sim/outliers.h"

#include <algorithm>
#include <cmath>

#include "sim/rng.h"
#include "sim/stream_purpose.h"

namespace cdpr::sim {
namespace {

// `count` distinct row indices of [0, rows), by a partial Fisher-Yates shuffle.
std::vector<int> choose_rows(Rng& rng, int rows, int count) {
  std::vector<int> order(rows);
  for (int k = 0; k < rows; ++k) order[k] = k;
  for (int k = 0; k < count; ++k) {
    const int pick = k + static_cast<int>(rng.uniform() * (rows - k));
    std::swap(order[k], order[std::min(pick, rows - 1)]);
  }
  order.resize(count);
  std::sort(order.begin(), order.end());
  return order;
}

int row_count(double fraction, int rows) {
  if (!(fraction > 0.0) || rows == 0) return 0;
  return std::clamp(static_cast<int>(std::lround(fraction * rows)), 1, rows);
}

double signed_uniform(Rng& rng, double low, double high) {
  const double magnitude = rng.uniform(low, high);
  return rng.uniform() < 0.5 ? -magnitude : magnitude;
}

}  // namespace

std::vector<SensorReading> plant_gross_errors(const GrossErrors& errors, std::uint64_t seed, int reference_cable,
                                              std::vector<Sample>& samples) {
  std::vector<SensorReading> planted;
  const int rows = static_cast<int>(samples.size());
  Rng encoder_rng = Rng::stream(seed, kStreamEncoderOutliers);
  for (int k : choose_rows(encoder_rng, rows, row_count(errors.encoder_fraction, rows))) {
    const int cable = std::min(static_cast<int>(encoder_rng.uniform() * kCableCount), kCableCount - 1);
    const double error = signed_uniform(encoder_rng, errors.encoder_min_m, errors.encoder_max_m);
    samples[k].encoder_m[cable] += error;
    planted.push_back({samples[k].id, SensorKind::kEncoder, cable, error});
  }
  Rng force_rng = Rng::stream(seed, kStreamForceSpikes);
  for (int k : choose_rows(force_rng, rows, row_count(errors.force_fraction, rows))) {
    const double error = signed_uniform(force_rng, errors.force_min_n, errors.force_max_n);
    samples[k].force_n += error;
    planted.push_back({samples[k].id, SensorKind::kForce, reference_cable, error});
  }
  std::sort(planted.begin(), planted.end(), [](const SensorReading& a, const SensorReading& b) {
    return a.row != b.row ? a.row < b.row : a.sensor < b.sensor;
  });
  return planted;
}

}  // namespace cdpr::sim
