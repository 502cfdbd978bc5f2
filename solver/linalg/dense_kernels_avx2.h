#pragma once
// add_transposed_product, add_transposed_times_vector,
// solve_upper_transposed_rows and all_finite (dense_kernels.h) four doubles
// at a time, for x86-64 processors with AVX2. Only dense_kernels_avx2.cc is
// compiled with -mavx2, and dense_kernels.cc calls these only when the
// processor has AVX2, so the library runs on any x86-64. Every sum runs
// over the depth in the same order as the portable kernels, with no fused
// multiply-add: both give the same bits
// (tests/solver/linalg/dense_kernels_test.cc).
//
// Built when CDPR_AVX2_KERNELS is defined (x86-64 targets; solver/CMakeLists.txt).

#include <cstddef>

namespace cdpr::avx2 {

void add_transposed_product(int depth, int rows, int cols, const double* x, int ldx, const double* y, int ldy,
                            double* out, int ldo, double sign, bool upper);
void add_transposed_times_vector(int depth, int cols, const double* x, int ldx, const double* v, double sign,
                                 double* out);
void solve_upper_transposed_rows(int d, const double* u, const double* inverse, int m, const double* b, double* w);
bool all_finite(const double* v, std::size_t n);

}  // namespace cdpr::avx2
