#pragma once

#include <algorithm>

namespace cdpr {

// Rows [first, end) of a factor's residual vector (a residual block of a
// BlockJacobian).
struct RowRange {
  int first = 0, end = 0;
};

inline int depth(RowRange r) { return std::max(0, r.end - r.first); }
inline bool same_rows(RowRange a, RowRange b) { return a.first == b.first && a.end == b.end; }
inline RowRange common_rows(RowRange a, RowRange b) { return {std::max(a.first, b.first), std::min(a.end, b.end)}; }
// The smallest range holding both (an empty one adds nothing).
inline RowRange hull(RowRange a, RowRange b) {
  if (depth(a) == 0) return b;
  if (depth(b) == 0) return a;
  return {std::min(a.first, b.first), std::max(a.end, b.end)};
}

}  // namespace cdpr
