#pragma once
// Axis ticks on the 1-2-5 series (..., 0.1, 0.2, 0.5, 1, 2, 5, 10, ...):
// round numbers a reader can interpolate between, with the axis widened to
// the ticks around the data so that no point sits outside the frame.

#include <string>
#include <vector>

namespace cdpr::report {

struct Ticks {
  double lo = 0.0, hi = 1.0;  // the axis range: the first and last tick
  double step = 1.0;          // 1, 2 or 5 times a power of ten
  std::vector<double> values; // lo, lo + step, ..., hi
};

// Ticks covering [lo, hi] with at most `max_count` + 1 values (the fewest
// intervals of a 1-2-5 step that still hold the range). A range of zero
// width (one value) is widened around it first.
Ticks nice_ticks(double lo, double hi, int max_count = 5);

// A tick value with just the decimals its step needs ("0.005", "-2", "150");
// never "-0".
std::string tick_label(double value, double step);

}  // namespace cdpr::report
