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
// ... in pairs of doubles whatever the processor (as add_transposed_product_portable).
void add_transposed_times_vector_portable(int depth, int cols, const double* x, int ldx, const double* v,
                                          double sign, double* out);

// out[k] -= sum_{c < cols} x(k, c) v[c] for k < rows (x v).
void subtract_times_vector(int rows, int cols, const double* x, int ldx, const double* v, double* out);

// Whether all n values are finite: x * 0 is 0 for every finite x and NaN
// for an infinity or NaN, so one branch-free sum over pairs tells (a test
// per value, or scalar sums, cost several times more on the solver's
// whole Jacobian buffers).
bool all_finite(const double* v, std::size_t n);
// ... in pairs of doubles whatever the processor (as add_transposed_product_portable).
bool all_finite_portable(const double* v, std::size_t n);

// W = U'^-1 B for the d x d upper triangular U (column-major; `inverse`:
// the reciprocals of its diagonal) and the d x m row-major B and W (forward
// substitution, a whole row at a time).
void solve_upper_transposed_rows(int d, const double* u, const double* inverse, int m, const double* b, double* w);
// ... in pairs of doubles whatever the processor (as add_transposed_product_portable).
void solve_upper_transposed_rows_portable(int d, const double* u, const double* inverse, int m, const double* b,
                                          double* w);

}  // namespace cdpr
