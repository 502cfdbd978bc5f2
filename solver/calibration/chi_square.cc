#include "solver/calibration/chi_square.h"

#include <cmath>
#include <numbers>

namespace cdpr {

double normal_upper_tail(double z) { return 0.5 * std::erfc(z / std::numbers::sqrt2); }

double chi_square_upper_tail(double x, int k) {
  if (k <= 0) return x > 0.0 ? 0.0 : 1.0;
  if (x <= 0.0) return 1.0;
  if (k > 30) {
    const double s = 2.0 / (9.0 * k);
    return normal_upper_tail((std::cbrt(x / k) - (1.0 - s)) / std::sqrt(s));
  }
  // Q(k/2, x/2) by its finite series: for even k, e^-h sum_{i<k/2} h^i / i!;
  // for odd k, erfc(sqrt h) + e^-h sum_{i=1}^{(k-1)/2} h^(i-1/2) / Gamma(i+1/2)
  // (h = x/2), each term from the one before (no factorial overflows).
  const double h = 0.5 * x;
  double sum = 0.0;
  if (k % 2 == 0) {
    double term = std::exp(-h);
    for (int i = 0; i < k / 2; ++i) {
      sum += term;
      term *= h / (i + 1);
    }
    return sum;
  }
  double term = std::exp(-h) * std::sqrt(h) / std::tgamma(1.5);
  for (int i = 1; i <= (k - 1) / 2; ++i) {
    sum += term;
    term *= h / (i + 0.5);
  }
  return std::erfc(std::sqrt(h)) + sum;
}

double scaled_chi_square_upper_tail(double x, double mean, double variance) {
  if (mean <= 0.0) return x > 0.0 ? 0.0 : 1.0;
  if (x <= 0.0) return 1.0;
  if (variance <= 0.0) variance = 2.0 * mean;
  const double nu = 2.0 * mean * mean / variance;  // x / a / nu = x / mean
  const double s = 2.0 / (9.0 * nu);
  return normal_upper_tail((std::cbrt(x / mean) - (1.0 - s)) / std::sqrt(s));
}

}  // namespace cdpr
