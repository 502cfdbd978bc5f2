#include "solver/linalg/dense_kernels.h"

#include <algorithm>
#include <cstring>

#ifdef CDPR_AVX2_KERNELS
#include "solver/linalg/dense_kernels_avx2.h"
#endif

namespace cdpr {
namespace {

// Two doubles in one register where the target has one (SSE2, NEON).
typedef double Pair __attribute__((vector_size(2 * sizeof(double))));

Pair load(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);  // unaligned: rows start anywhere
  return v;
}
void store(double* p, Pair v) { std::memcpy(p, &v, sizeof v); }
Pair splat(double a) { return Pair{a, a}; }

// Rows [r, r + 2 Pairs) of columns c .. c + Cols - 1: the x rows are loaded
// two at a time and multiplied by one broadcast y entry per column, so the
// sums of a tile stay in registers over the whole depth.
template <int Pairs, int Cols>
void tile(int depth, int r, int c, const double* x, int ldx, const double* y, int ldy, double* out, int ldo,
          double sign) {
  Pair sum[Pairs][Cols] = {};
  for (int k = 0; k < depth; ++k) {
    const double* xk = x + k * ldx + r;
    const double* yk = y + k * ldy + c;
    Pair xv[Pairs];
    for (int p = 0; p < Pairs; ++p) xv[p] = load(xk + 2 * p);
    for (int q = 0; q < Cols; ++q) {
      const Pair yv = splat(yk[q]);
      for (int p = 0; p < Pairs; ++p) sum[p][q] += xv[p] * yv;
    }
  }
  const Pair s = splat(sign);
  for (int q = 0; q < Cols; ++q) {
    for (int p = 0; p < Pairs; ++p) {
      double* o = out + r + 2 * p + ldo * (c + q);
      store(o, load(o) + s * sum[p][q]);
    }
  }
}

// Row r alone (an odd row count's last row) of columns c .. c + Cols - 1.
template <int Cols>
void row_tile(int depth, int r, int c, const double* x, int ldx, const double* y, int ldy, double* out, int ldo,
              double sign) {
  double sum[Cols] = {};
  for (int k = 0; k < depth; ++k) {
    const double xk = x[k * ldx + r];
    for (int q = 0; q < Cols; ++q) sum[q] += xk * y[k * ldy + c + q];
  }
  for (int q = 0; q < Cols; ++q) out[r + ldo * (c + q)] += sign * sum[q];
}

Pair swapped(Pair v) { return __builtin_shufflevector(v, v, 1, 0); }

// Rows [r, r + 4) of columns [c, c + 4), the bulk of the work: a pair of x
// rows times a pair of y columns gives the 2x2 block's diagonal (x * y) and
// anti-diagonal (x * swapped y) in two products, four loads and two shuffles
// per depth step for 16 multiply-adds, all 8 sums in registers.
void tile4x4(int depth, int r, int c, const double* x, int ldx, const double* y, int ldy, double* out, int ldo,
             double sign) {
  // Named sums, not arrays: GCC at -O2 keeps arrays of vectors in memory.
  Pair d00 = {}, d01 = {}, d10 = {}, d11 = {}, a00 = {}, a01 = {}, a10 = {}, a11 = {};
  for (int k = 0; k < depth; ++k) {
    const double* xk = x + k * ldx + r;
    const double* yk = y + k * ldy + c;
    const Pair x0 = load(xk), x1 = load(xk + 2), y0 = load(yk), y1 = load(yk + 2);
    const Pair s0 = swapped(y0), s1 = swapped(y1);
    d00 += x0 * y0;
    a00 += x0 * s0;
    d01 += x0 * y1;
    a01 += x0 * s1;
    d10 += x1 * y0;
    a10 += x1 * s0;
    d11 += x1 * y1;
    a11 += x1 * s1;
  }
  const Pair s = splat(sign);
  // (x_r y_c, x_r+1 y_c+1) and (x_r y_c+1, x_r+1 y_c) give columns c and c + 1.
  auto add = [&](int p, int q, Pair diagonal, Pair anti) {
    double* even = out + r + 2 * p + ldo * (c + 2 * q);
    double* odd = even + ldo;
    store(even, load(even) + s * __builtin_shufflevector(diagonal, anti, 0, 3));
    store(odd, load(odd) + s * __builtin_shufflevector(anti, diagonal, 0, 3));
  };
  add(0, 0, d00, a00);
  add(0, 1, d01, a01);
  add(1, 0, d10, a10);
  add(1, 1, d11, a11);
}

template <int Cols>
void column_tiles(int depth, int row_end, int c, const double* x, int ldx, const double* y, int ldy, double* out,
                  int ldo, double sign) {
  int r = 0;
  for (; r + 4 <= row_end; r += 4) tile<2, Cols>(depth, r, c, x, ldx, y, ldy, out, ldo, sign);
  for (; r + 2 <= row_end; r += 2) tile<1, Cols>(depth, r, c, x, ldx, y, ldy, out, ldo, sign);
  if (r < row_end) row_tile<Cols>(depth, r, c, x, ldx, y, ldy, out, ldo, sign);
}

}  // namespace

// The J^T J and S -= W'W products are a fifth of a calibration's solve, the
// J^T r products and the eliminations' substitutions a tenth: twice the
// width where the processor has it, the same bits either way.
#ifdef CDPR_AVX2_KERNELS
namespace {
bool use_avx2() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}
}  // namespace
#endif

void add_transposed_product(int depth, int rows, int cols, const double* x, int ldx, const double* y, int ldy,
                            double* out, int ldo, double sign, bool upper) {
#ifdef CDPR_AVX2_KERNELS
  if (use_avx2()) return avx2::add_transposed_product(depth, rows, cols, x, ldx, y, ldy, out, ldo, sign, upper);
#endif
  add_transposed_product_portable(depth, rows, cols, x, ldx, y, ldy, out, ldo, sign, upper);
}

void add_transposed_times_vector(int depth, int cols, const double* x, int ldx, const double* v, double sign,
                                 double* out) {
#ifdef CDPR_AVX2_KERNELS
  if (use_avx2()) return avx2::add_transposed_times_vector(depth, cols, x, ldx, v, sign, out);
#endif
  add_transposed_times_vector_portable(depth, cols, x, ldx, v, sign, out);
}

void solve_upper_transposed_rows(int d, const double* u, const double* inverse, int m, const double* b, double* w) {
#ifdef CDPR_AVX2_KERNELS
  if (use_avx2()) return avx2::solve_upper_transposed_rows(d, u, inverse, m, b, w);
#endif
  solve_upper_transposed_rows_portable(d, u, inverse, m, b, w);
}

void add_transposed_product_portable(int depth, int rows, int cols, const double* x, int ldx, const double* y,
                                     int ldy, double* out, int ldo, double sign, bool upper) {
  int c = 0;
  for (; c + 4 <= cols; c += 4) {
    const int row_end = upper ? std::min(rows, c + 4) : rows;
    int r = 0;
    for (; r + 4 <= row_end; r += 4) tile4x4(depth, r, c, x, ldx, y, ldy, out, ldo, sign);
    // The last rows (fewer than four) in the pair kernels.
    column_tiles<2>(depth, row_end - r, c, x + r, ldx, y, ldy, out + r, ldo, sign);
    column_tiles<2>(depth, row_end - r, c + 2, x + r, ldx, y, ldy, out + r, ldo, sign);
  }
  for (; c + 2 <= cols; c += 2) {
    column_tiles<2>(depth, upper ? std::min(rows, c + 2) : rows, c, x, ldx, y, ldy, out, ldo, sign);
  }
  if (c < cols) column_tiles<1>(depth, upper ? std::min(rows, c + 1) : rows, c, x, ldx, y, ldy, out, ldo, sign);
}

void add_transposed_times_vector_portable(int depth, int cols, const double* x, int ldx, const double* v,
                                          double sign, double* out) {
  int c = 0;
  // Eight columns at a time: four independent sums, where one alone would
  // wait on its own additions down the whole depth.
  for (; c + 8 <= cols; c += 8) {
    Pair s0 = {}, s1 = {}, s2 = {}, s3 = {};
    for (int k = 0; k < depth; ++k) {
      const double* xk = x + k * ldx + c;
      const Pair vk = splat(v[k]);
      s0 += load(xk) * vk;
      s1 += load(xk + 2) * vk;
      s2 += load(xk + 4) * vk;
      s3 += load(xk + 6) * vk;
    }
    const Pair s = splat(sign);
    store(out + c, load(out + c) + s * s0);
    store(out + c + 2, load(out + c + 2) + s * s1);
    store(out + c + 4, load(out + c + 4) + s * s2);
    store(out + c + 6, load(out + c + 6) + s * s3);
  }
  for (; c + 2 <= cols; c += 2) {
    Pair sum = {};
    for (int k = 0; k < depth; ++k) sum += load(x + k * ldx + c) * splat(v[k]);
    store(out + c, load(out + c) + splat(sign) * sum);
  }
  if (c < cols) {
    double sum = 0.0;
    for (int k = 0; k < depth; ++k) sum += x[k * ldx + c] * v[k];
    out[c] += sign * sum;
  }
}

void subtract_times_vector(int rows, int cols, const double* x, int ldx, const double* v, double* out) {
  for (int k = 0; k < rows; ++k) {
    const double* xk = x + k * ldx;
    Pair sum = {};
    int c = 0;
    for (; c + 2 <= cols; c += 2) sum += load(xk + c) * load(v + c);
    double dot = sum[0] + sum[1];
    if (c < cols) dot += xk[c] * v[c];
    out[k] -= dot;
  }
}

bool all_finite(const double* v, std::size_t n) {
#ifdef CDPR_AVX2_KERNELS
  if (use_avx2()) return avx2::all_finite(v, n);
#endif
  return all_finite_portable(v, n);
}

bool all_finite_portable(const double* v, std::size_t n) {
  Pair s0 = {}, s1 = {};
  const Pair zero = {};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += load(v + i) * zero;
    s1 += load(v + i + 2) * zero;
  }
  double rest = 0.0;
  for (; i < n; ++i) rest += v[i] * 0.0;
  const Pair sum = s0 + s1;
  return sum[0] + sum[1] + rest == 0.0;
}

void solve_upper_transposed_rows_portable(int d, const double* u, const double* inverse, int m, const double* b,
                                          double* w) {
  int q = 0;
  // Eight columns at a time, their four pairs in registers down all d rows.
  for (; q + 8 <= m; q += 8) {
    for (int i = 0; i < d; ++i) {
      const double* ui = u + d * i;  // column i of U: U_pi for p <= i
      const double* bi = b + i * m + q;
      Pair v0 = load(bi), v1 = load(bi + 2), v2 = load(bi + 4), v3 = load(bi + 6);
      for (int p = 0; p < i; ++p) {
        const Pair factor = splat(ui[p]);
        const double* wp = w + p * m + q;
        v0 -= factor * load(wp);
        v1 -= factor * load(wp + 2);
        v2 -= factor * load(wp + 4);
        v3 -= factor * load(wp + 6);
      }
      const Pair scale = splat(inverse[i]);
      double* wi = w + i * m + q;
      store(wi, v0 * scale);
      store(wi + 2, v1 * scale);
      store(wi + 4, v2 * scale);
      store(wi + 6, v3 * scale);
    }
  }
  for (; q < m; ++q) {
    for (int i = 0; i < d; ++i) {
      const double* ui = u + d * i;
      double v = b[i * m + q];
      for (int p = 0; p < i; ++p) v -= ui[p] * w[p * m + q];
      w[i * m + q] = v * inverse[i];
    }
  }
}

}  // namespace cdpr
