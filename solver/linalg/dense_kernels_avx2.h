#pragma once
// add_transposed_product (dense_kernels.h) four doubles at a time, for
// x86-64 processors with AVX2. Only dense_kernels_avx2.cc is compiled with
// -mavx2, and add_transposed_product calls this only when the processor has
// AVX2, so the library runs on any x86-64. Every sum runs over the depth in
// the same order as the portable kernels, with no fused multiply-add: both
// give the same bits (tests/solver/linalg/dense_kernels_test.cc).
//
// Built when CDPR_AVX2_KERNELS is defined (x86-64 targets; solver/CMakeLists.txt).

namespace cdpr::avx2 {

void add_transposed_product(int depth, int rows, int cols, const double* x, int ldx, const double* y, int ldy,
                            double* out, int ldo, double sign, bool upper);

}  // namespace cdpr::avx2
