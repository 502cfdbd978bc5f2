#include "src/calibration/window_statistics.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace cdpr::calibration {

WindowStatistics window_statistics(std::span<const double> values, double sigma_floor) {
  assert(!values.empty() && sigma_floor > 0.0);
  const std::size_t n = values.size();
  WindowStatistics out;
  double sum = 0.0;
  for (const double v : values) sum += v;
  out.mean = sum / static_cast<double>(n);
  double c0 = 0.0;
  for (const double v : values) c0 += (v - out.mean) * (v - out.mean);
  out.effective_count = 1.0;
  if (n >= 2 && c0 > 0.0) {
    out.scatter = std::sqrt(c0 / static_cast<double>(n - 1));
    // Autocovariances with the biased (1/n) normalisation, which keeps the
    // estimate of tau stable at long lags.
    double tau = 1.0;
    for (std::size_t lag = 1; lag < n; ++lag) {
      double ck = 0.0;
      for (std::size_t t = 0; t + lag < n; ++t) ck += (values[t] - out.mean) * (values[t + lag] - out.mean);
      const double rho = ck / c0;
      if (!(rho > 0.0)) break;
      tau += 2.0 * rho;
    }
    out.effective_count = std::clamp(static_cast<double>(n) / tau, 1.0, static_cast<double>(n));
  }
  out.sigma_of_mean = std::max(out.scatter, sigma_floor) / std::sqrt(out.effective_count);
  return out;
}

}  // namespace cdpr::calibration
