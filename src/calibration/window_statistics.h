#pragma once
// The standard error of the mean of a rest window's readings: how well the
// average that becomes a sample row knows the reading it stands for.
//
//   sigma_mean = max(s, sigma_floor) / sqrt(n_eff)
//
// s is the readings' own standard deviation in the window. sigma_floor is
// robot.toml's per-reading sigma: a window quieter than the sensor is
// specified to be (a reading held between two updates, a quantised value)
// cannot claim more than the sensor's resolution justifies, so the scatter
// is never taken below it. n_eff is the effective number of independent
// readings, n / tau with the integrated autocorrelation time
// tau = 1 + 2 sum_k rho_k, summed over the lags k >= 1 while the sample
// autocorrelation rho_k stays positive (the initial positive sequence) and
// clamped to [1, n]: white noise gives n_eff close to n; a reading repeated
// m times between sensor updates, or a slow drift or sway, gives fewer.
// A constant window (s = 0) gives no evidence of independence: n_eff = 1,
// sigma_mean = sigma_floor.
// Pure function of the values; allocates nothing; O(n x lags).

#include <span>

namespace cdpr::calibration {

struct WindowStatistics {
  double mean = 0.0;
  double scatter = 0.0;         // s, the sample standard deviation (n - 1)
  double effective_count = 0.0; // n_eff in [1, n]
  double sigma_of_mean = 0.0;   // max(s, floor) / sqrt(n_eff)
};

// Precondition: values not empty, sigma_floor > 0.
WindowStatistics window_statistics(std::span<const double> values, double sigma_floor);

}  // namespace cdpr::calibration
