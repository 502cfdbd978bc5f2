#pragma once
// Small dense products for the normal equations of one pose group (J^T J of
// a factor, S -= W'W of an elimination): a few to a few dozen rows and
// columns, too small for a blocked BLAS and too large to leave to scalar
// loops. The inner loops run on pairs of doubles through the compiler's
// generic vector extension, which GCC and Clang lower to SSE2 on x86-64 (the
// baseline, no -march needed) and to NEON or scalar code elsewhere, so every
// translation unit sees the same code whatever the target.
//
// Row-major inputs (x(k, r) = x[k * ldx + r]), column-major output
// (out(r, c) = out[r + ldo * c]). None of it allocates.

#include <cstddef>

namespace cdpr {

// out(r, c) += sign * sum_{k < depth} x(k, r) y(k, c) for r < rows, c < cols.
// When `upper` (then x and y are the same columns and rows == cols), only
// r <= c is needed; the entry just below the diagonal in each pair of columns
// may be written too, so the strictly lower triangle of `out` is scratch.
void add_transposed_product(int depth, int rows, int cols, const double* x, int ldx, const double* y, int ldy,
                            double* out, int ldo, double sign, bool upper);

// add_transposed_product in pairs of doubles whatever the processor (what it
// runs where solver/linalg/dense_kernels_avx2.h does not apply; tests compare them).
void add_transposed_product_portable(int depth, int rows, int cols, const double* x, int ldx, const double* y,
                                     int ldy, double* out, int ldo, double sign, bool upper);

// out[c] += sign * sum_{k < depth} x(k, c) v[k] for c < cols (x' v).
void add_transposed_times_vector(int depth, int cols, const double* x, int ldx, const double* v, double sign,
                                 double* out);

// out[k] -= sum_{c < cols} x(k, c) v[c] for k < rows (x v).
void subtract_times_vector(int rows, int cols, const double* x, int ldx, const double* v, double* out);

// Whether all n values are finite: x * 0 is 0 for every finite x and NaN
// for an infinity or NaN, so one branch-free sum over pairs tells (a test
// per value, or scalar sums, cost several times more on the solver's
// whole Jacobian buffers).
bool all_finite(const double* v, std::size_t n);

// W = U'^-1 B for the d x d upper triangular U (column-major; `inverse`:
// the reciprocals of its diagonal) and the d x m row-major B and W (forward
// substitution, a whole row at a time).
void solve_upper_transposed_rows(int d, const double* u, const double* inverse, int m, const double* b, double* w);

// dst(i, c) = block(i, c) for a row-major m x d block into rows of stride
// `ld` (a factor's Jacobian block into a wider row-major matrix): d fixed
// for the tangent sizes that occur (D > 0), so each row is a few moves (a
// generic loop, or std::copy's memmove per row, cost several times more
// than the values); D = 0 takes the runtime d. Inline: it runs once per
// block of every factor.
template <int D>
inline void copy_block_columns_sized(int m, int d, const double* block, double* dst, int ld) {
  if constexpr (D > 0) d = D;
  for (int i = 0; i < m; ++i) {
    for (int c = 0; c < d; ++c) dst[i * ld + c] = block[i * d + c];
  }
}
inline void copy_block_columns(int m, int d, const double* block, double* dst, int ld) {
  switch (d) {
    case 1: return copy_block_columns_sized<1>(m, d, block, dst, ld);
    case 2: return copy_block_columns_sized<2>(m, d, block, dst, ld);
    case 3: return copy_block_columns_sized<3>(m, d, block, dst, ld);
    case 6: return copy_block_columns_sized<6>(m, d, block, dst, ld);
    default: return copy_block_columns_sized<0>(m, d, block, dst, ld);
  }
}

}  // namespace cdpr
