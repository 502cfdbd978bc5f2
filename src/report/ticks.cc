#include "src/report/ticks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cdpr::report {

Ticks nice_ticks(double lo, double hi, int max_count) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0.0, hi = 1.0;
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(lo))) {
    const double pad = lo == 0.0 ? 1.0 : 0.1 * std::abs(lo);
    lo -= pad;
    hi += pad;
  }
  max_count = std::max(1, max_count);
  const double rough = (hi - lo) / max_count;
  double power = std::pow(10.0, std::floor(std::log10(rough)));
  Ticks t;
  for (;;) {
    for (double m : {1.0, 2.0, 5.0}) {
      t.step = m * power;
      t.lo = std::floor(lo / t.step + 1e-9) * t.step;
      t.hi = std::ceil(hi / t.step - 1e-9) * t.step;
      if (std::lround((t.hi - t.lo) / t.step) <= max_count) break;
    }
    if (std::lround((t.hi - t.lo) / t.step) <= max_count) break;
    power *= 10.0;
  }
  const long n = std::lround((t.hi - t.lo) / t.step);
  for (long k = 0; k <= n; ++k) {
    const double v = t.lo + static_cast<double>(k) * t.step;
    t.values.push_back(std::abs(v) < 1e-9 * t.step ? 0.0 : v);
  }
  return t;
}

std::string tick_label(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(value) < 0.5 * step) value = 0.0;
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

}  // namespace cdpr::report
