#include "solver/linalg/dense_kernels_avx2.h"

#include "solver/linalg/dense_kernels.h"

#include <algorithm>
#include <cstring>

namespace cdpr::avx2 {
namespace {

// Four doubles in one register. The helpers below mirror dense_kernels.cc's
// on purpose, not shared through a header: an inline function compiled here
// (with -mavx2) and there may be merged by the linker into one copy, which
// could then be this file's AVX code run on a processor without AVX2.
typedef double Quad __attribute__((vector_size(4 * sizeof(double))));

Quad load(const double* p) {
  Quad v;
  std::memcpy(&v, p, sizeof v);  // unaligned: rows start anywhere
  return v;
}
void store(double* p, Quad v) { std::memcpy(p, &v, sizeof v); }
Quad splat(double a) { return Quad{a, a, a, a}; }

// Rows [0, 8) x columns [0, 4) of the block at x, y, out: two quads of x
// rows times one broadcast y entry per column, 32 multiply-adds a depth step
// with all eight sums in registers (named, not an array: GCC at -O2 keeps
// arrays of vectors in memory).
void tile8x4(int depth, const double* x, int ldx, const double* y, int ldy, double* out, int ldo, double sign) {
  Quad a0 = {}, a1 = {}, a2 = {}, a3 = {}, b0 = {}, b1 = {}, b2 = {}, b3 = {};
#pragma GCC unroll 4
  for (int k = 0; k < depth; ++k) {
    const double* xk = x + k * ldx;
    const double* yk = y + k * ldy;
    const Quad x0 = load(xk), x1 = load(xk + 4);
    const Quad y0 = splat(yk[0]), y1 = splat(yk[1]), y2 = splat(yk[2]), y3 = splat(yk[3]);
    a0 += x0 * y0;
    b0 += x1 * y0;
    a1 += x0 * y1;
    b1 += x1 * y1;
    a2 += x0 * y2;
    b2 += x1 * y2;
    a3 += x0 * y3;
    b3 += x1 * y3;
  }
  const Quad s = splat(sign);
  auto add = [&](int q, Quad top, Quad bottom) {
    double* o = out + ldo * q;
    store(o, load(o) + s * top);
    store(o + 4, load(o + 4) + s * bottom);
  };
  add(0, a0, b0);
  add(1, a1, b1);
  add(2, a2, b2);
  add(3, a3, b3);
}

// Rows [0, 4) x columns [0, Cols), Cols <= 4 (named sums, as above).
template <int Cols>
void tile4(int depth, const double* x, int ldx, const double* y, int ldy, double* out, int ldo, double sign) {
  Quad a0 = {}, a1 = {}, a2 = {}, a3 = {};
#pragma GCC unroll 4
  for (int k = 0; k < depth; ++k) {
    const Quad xv = load(x + k * ldx);
    const double* yk = y + k * ldy;
    a0 += xv * splat(yk[0]);
    if constexpr (Cols > 1) a1 += xv * splat(yk[1]);
    if constexpr (Cols > 2) a2 += xv * splat(yk[2]);
    if constexpr (Cols > 3) a3 += xv * splat(yk[3]);
  }
  const Quad s = splat(sign);
  store(out, load(out) + s * a0);
  if constexpr (Cols > 1) store(out + ldo, load(out + ldo) + s * a1);
  if constexpr (Cols > 2) store(out + 2 * ldo, load(out + 2 * ldo) + s * a2);
  if constexpr (Cols > 3) store(out + 3 * ldo, load(out + 3 * ldo) + s * a3);
}

// Row 0 alone x columns [0, Cols).
template <int Cols>
void row1(int depth, const double* x, int ldx, const double* y, int ldy, double* out, int ldo, double sign) {
  double sum[Cols] = {};
  for (int k = 0; k < depth; ++k) {
    const double xk = x[k * ldx];
    for (int q = 0; q < Cols; ++q) sum[q] += xk * y[k * ldy + q];
  }
  for (int q = 0; q < Cols; ++q) out[ldo * q] += sign * sum[q];
}

// Rows [0, rows) x columns [0, Cols).
template <int Cols>
void columns(int depth, int rows, const double* x, int ldx, const double* y, int ldy, double* out, int ldo,
             double sign) {
  int r = 0;
  if constexpr (Cols == 4) {
    for (; r + 8 <= rows; r += 8) tile8x4(depth, x + r, ldx, y, ldy, out + r, ldo, sign);
  }
  for (; r + 4 <= rows; r += 4) tile4<Cols>(depth, x + r, ldx, y, ldy, out + r, ldo, sign);
  for (; r < rows; ++r) row1<Cols>(depth, x + r, ldx, y, ldy, out + r, ldo, sign);
}

}  // namespace

void add_transposed_product(int depth, int rows, int cols, const double* x, int ldx, const double* y, int ldy,
                            double* out, int ldo, double sign, bool upper) {
  int c = 0;
  for (; c + 4 <= cols; c += 4) {
    columns<4>(depth, upper ? std::min(rows, c + 4) : rows, x, ldx, y + c, ldy, out + ldo * c, ldo, sign);
  }
  const int rest = cols - c, row_end = upper ? std::min(rows, cols) : rows;
  y += c;
  out += ldo * c;
  switch (rest) {
    case 3: return columns<3>(depth, row_end, x, ldx, y, ldy, out, ldo, sign);
    case 2: return columns<2>(depth, row_end, x, ldx, y, ldy, out, ldo, sign);
    case 1: return columns<1>(depth, row_end, x, ldx, y, ldy, out, ldo, sign);
  }
}

void add_transposed_times_vector(int depth, int cols, const double* x, int ldx, const double* v, double sign,
                                 double* out) {
  int c = 0;
  // Sixteen columns at a time: four independent sums, as the portable kernel's eight.
  for (; c + 16 <= cols; c += 16) {
    Quad s0 = {}, s1 = {}, s2 = {}, s3 = {};
    for (int k = 0; k < depth; ++k) {
      const double* xk = x + k * ldx + c;
      const Quad vk = splat(v[k]);
      s0 += load(xk) * vk;
      s1 += load(xk + 4) * vk;
      s2 += load(xk + 8) * vk;
      s3 += load(xk + 12) * vk;
    }
    const Quad s = splat(sign);
    store(out + c, load(out + c) + s * s0);
    store(out + c + 4, load(out + c + 4) + s * s1);
    store(out + c + 8, load(out + c + 8) + s * s2);
    store(out + c + 12, load(out + c + 12) + s * s3);
  }
  // Eight: two sums, one broadcast of v[k] for both (a factor's runs are
  // mostly 8 to 12 columns wide).
  for (; c + 8 <= cols; c += 8) {
    Quad s0 = {}, s1 = {};
#pragma GCC unroll 4
    for (int k = 0; k < depth; ++k) {
      const double* xk = x + k * ldx + c;
      const Quad vk = splat(v[k]);
      s0 += load(xk) * vk;
      s1 += load(xk + 4) * vk;
    }
    const Quad s = splat(sign);
    store(out + c, load(out + c) + s * s0);
    store(out + c + 4, load(out + c + 4) + s * s1);
  }
  for (; c + 4 <= cols; c += 4) {
    Quad sum = {};
#pragma GCC unroll 4
    for (int k = 0; k < depth; ++k) sum += load(x + k * ldx + c) * splat(v[k]);
    store(out + c, load(out + c) + splat(sign) * sum);
  }
  // The last three columns or fewer, each its own sum down the depth (as
  // the portable kernel's pairs and single column: the same bits), here
  // rather than by a call.
  for (; c < cols; ++c) {
    double sum = 0.0;
    for (int k = 0; k < depth; ++k) sum += x[k * ldx + c] * v[k];
    out[c] += sign * sum;
  }
}

namespace {

// solve_upper_transposed_rows for d = D when D > 0 (known at compile time, the
// row loops unroll completely: a pose group's d = 8 leaves no loop control
// in the substitution), else the runtime `dim`.
template <int D>
void solve_rows(int dim, const double* u, const double* inverse, int m, const double* b, double* w) {
  const int d = D > 0 ? D : dim;
  int q = 0;
  // Eight columns at a time, their two quads in registers down all d rows.
  for (; q + 8 <= m; q += 8) {
#pragma GCC unroll 16
    for (int i = 0; i < d; ++i) {
      const double* ui = u + d * i;  // column i of U: U_pi for p <= i
      const double* bi = b + i * m + q;
      Quad v0 = load(bi), v1 = load(bi + 4);
#pragma GCC unroll 16
      for (int p = 0; p < i; ++p) {
        const Quad factor = splat(ui[p]);
        const double* wp = w + p * m + q;
        v0 -= factor * load(wp);
        v1 -= factor * load(wp + 4);
      }
      const Quad scale = splat(inverse[i]);
      double* wi = w + i * m + q;
      store(wi, v0 * scale);
      store(wi + 4, v1 * scale);
    }
  }
  for (; q + 4 <= m; q += 4) {
    for (int i = 0; i < d; ++i) {
      const double* ui = u + d * i;
      Quad v0 = load(b + i * m + q);
      for (int p = 0; p < i; ++p) v0 -= splat(ui[p]) * load(w + p * m + q);
      store(w + i * m + q, v0 * splat(inverse[i]));
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

}  // namespace

void solve_upper_transposed_rows(int d, const double* u, const double* inverse, int m, const double* b, double* w) {
  if (d == 8) return solve_rows<8>(d, u, inverse, m, b, w);
  solve_rows<0>(d, u, inverse, m, b, w);
}

bool all_finite(const double* v, std::size_t n) {
  Quad s0 = {}, s1 = {};
  const Quad zero = {};
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    s0 += load(v + i) * zero;
    s1 += load(v + i + 4) * zero;
  }
  const Quad sum = s0 + s1;
  return sum[0] + sum[1] + sum[2] + sum[3] == 0.0 && cdpr::all_finite_portable(v + i, n - i);
}

}  // namespace cdpr::avx2
