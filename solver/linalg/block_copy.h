#pragma once
// Copying a factor's row-major Jacobian block into a wider row-major
// matrix (the gathered rows of SchurComplement, the score test's rows).
// Kept apart from dense_kernels.h, which dense_kernels_avx2.cc includes:
// an inline function there, compiled with -mavx2 too, could be merged by
// the linker into the AVX2 copy.

#include <cstring>

namespace cdpr {

// dst(i, c) = block(i, c) for a row-major m x d block into rows of stride
// `ld` (a factor's Jacobian block into a wider row-major matrix): d fixed
// for the tangent sizes that occur (D > 0), so each row is one fixed-size
// memcpy, which the compiler turns into a few vector moves (an element
// loop, which may not assume that the two buffers are apart, moves one
// double at a time; std::copy's memmove per row costs a call); D = 0 takes
// the runtime d. Inline: it runs once per block of every factor.
template <int D>
inline void copy_block_columns_sized(int m, int d, const double* block, double* dst, int ld) {
  if constexpr (D > 0) {
    for (int i = 0; i < m; ++i) std::memcpy(dst + i * ld, block + i * D, D * sizeof(double));
  } else {
    for (int i = 0; i < m; ++i) {
      for (int c = 0; c < d; ++c) dst[i * ld + c] = block[i * d + c];
    }
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
