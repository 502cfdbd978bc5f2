#pragma once
// The dense kernels of SchurComplement on one group's d x d blocks: the
// Cholesky factorisation of the damped block, the elimination of its
// coupling to the global columns, and the group's parts of a solve.

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "solver/linalg/dense_kernels.h"

namespace cdpr::group_kernels {

// Dense kernels on one group's d x d blocks (column-major). D > 0 is d
// known at compile time (the loops unroll completely for the common group
// sizes: GCC at -O2 would keep the triangular loops, whose control then
// costs about as much as their arithmetic), D = 0 takes the runtime `dim`.

// In-place Cholesky A = U'U of a block whose upper triangle holds A, and
// the reciprocals of U's diagonal into `inverse` (every solve with U
// multiplies by them: a division costs as much as a dozen multiply-adds and
// sits on the critical path of each substitution); false when A is not
// positive definite.
template <int D>
bool cholesky_upper(double* u, int dim, double* inverse) {
  const int d = D > 0 ? D : dim;
#pragma GCC unroll 16
  for (int j = 0; j < d; ++j) {
    double* uj = u + d * j;
#pragma GCC unroll 16
    for (int i = 0; i < j; ++i) {
      const double* ui = u + d * i;
      double s = uj[i];
#pragma GCC unroll 16
      for (int p = 0; p < i; ++p) s -= ui[p] * uj[p];
      uj[i] = s * inverse[i];
    }
    double s = uj[j];
#pragma GCC unroll 16
    for (int p = 0; p < j; ++p) s -= uj[p] * uj[p];
    if (!(s > 0.0)) return false;
    uj[j] = std::sqrt(s);
    inverse[j] = 1.0 / uj[j];
  }
  return true;
}

// Solves U'y = b in place (forward substitution).
template <int D>
void solve_upper_transposed(const double* u, const double* inverse, int dim, double* y) {
  const int d = D > 0 ? D : dim;
#pragma GCC unroll 16
  for (int i = 0; i < d; ++i) {
    const double* ui = u + d * i;
    double s = y[i];
#pragma GCC unroll 16
    for (int p = 0; p < i; ++p) s -= ui[p] * y[p];
    y[i] = s * inverse[i];
  }
}

// Solves U x = b in place (back substitution).
template <int D>
void solve_upper(const double* u, const double* inverse, int dim, double* x) {
  const int d = D > 0 ? D : dim;
#pragma GCC unroll 16
  for (int i = d - 1; i >= 0; --i) {
    double s = x[i];
#pragma GCC unroll 16
    for (int p = i + 1; p < d; ++p) s -= u[i + d * p] * x[p];
    x[i] = s * inverse[i];
  }
}

// One group's damped block factorised: U'U = A + D_A / radius, in place of
// its copy in u; false when not positive definite.
template <int D>
bool factor_group(int dim, const double* a, double* u, double* inverse, double radius, double min_diagonal,
                  double max_diagonal) {
  const int d = D > 0 ? D : dim;
#pragma GCC unroll 16
  for (int j = 0; j < d; ++j) {
#pragma GCC unroll 16
    for (int i = 0; i <= j; ++i) u[i + d * j] = a[i + d * j];
    u[j + d * j] += std::clamp(a[j + d * j], min_diagonal, max_diagonal) / radius;
  }
  return cholesky_upper<D>(u, d, inverse);
}

// B and W are d x m row-major (a row per local column, contiguous over the
// m coupled global columns), so the work below runs along contiguous rows.
// One group's elimination once U is known: W = U'^-1 B and S -= W'W over
// its coupled columns (ascending, so into the upper triangle of the n x n
// S; `first` >= 0 when they are the contiguous columns first, first + 1, ...).
inline void eliminate_group(int d, const double* u, const double* inverse, const double* b, double* w, int m,
                     const int* columns, int first, double* s, int n) {
  solve_upper_transposed_rows(d, u, inverse, m, b, w);
  // S -= W'W (upper triangle).
  if (first >= 0) {
    add_transposed_product(d, m, m, w, m, w, m, s + first + static_cast<std::size_t>(n) * first, n, -1.0, true);
    return;
  }
  for (int i = 0; i < d; ++i) {
    const double* wi = w + i * m;
    for (int q = 0; q < m; ++q) {
      double* s_column = s + static_cast<std::size_t>(n) * columns[q];
      for (int p = 0; p <= q; ++p) s_column[columns[p]] -= wi[p] * wi[q];
    }
  }
}

// The group's part of a solve, before the reduced system: y = U'^-1 b_l in
// place, reduced right-hand side -= W'y (`first` as in eliminate_group).
template <int D>
void forward_group(int dim, const double* u, const double* inverse, const double* w, int m, const int* columns,
                   int first, double* y, double* reduced) {
  const int d = D > 0 ? D : dim;
  solve_upper_transposed<D>(u, inverse, d, y);
  if (first >= 0) {
    add_transposed_times_vector(d, m, w, m, y, -1.0, reduced + first);
    return;
  }
  for (int i = 0; i < d; ++i) {
    for (int p = 0; p < m; ++p) reduced[columns[p]] -= w[i * m + p] * y[i];
  }
}

// ... and after it: x_l = U^-1 (y - W x_g) in place.
template <int D>
void backward_group(int dim, const double* u, const double* inverse, const double* w, int m, const int* columns,
                    int first, const double* x_global, double* y) {
  const int d = D > 0 ? D : dim;
  if (first >= 0) {
    subtract_times_vector(d, m, w, m, x_global + first, y);
  } else {
    for (int i = 0; i < d; ++i) {
      double dot = 0.0;
      for (int p = 0; p < m; ++p) dot += w[i * m + p] * x_global[columns[p]];
      y[i] -= dot;
    }
  }
  solve_upper<D>(u, inverse, d, y);
}

// Calls f(std::integral_constant<int, D>) with D the group size when the
// kernels above are compiled for it (a pose with its reference force: 8; a
// pose alone: 6), else D = 0 (runtime size).
template <typename F>
void for_group_dim(int dim, F&& f) {
  switch (dim) {
    case 8: f(std::integral_constant<int, 8>{}); break;
    case 6: f(std::integral_constant<int, 6>{}); break;
    default: f(std::integral_constant<int, 0>{});
  }
}

}  // namespace cdpr::group_kernels
