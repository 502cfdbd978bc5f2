#include "solver/linalg/dense_kernels.h"

#ifdef CDPR_AVX2_KERNELS
#include "solver/linalg/dense_kernels_avx2.h"
#endif

#include <limits>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

namespace cdpr {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

RowMajor random_matrix(int rows, int cols, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RowMajor m(rows, cols);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) m(i, j) = u(rng);
  }
  return m;
}

// Every tile path: 4x4 tiles, pairs of rows and columns, a single row or
// column, depths of 0 to 11, inside a larger output with its own stride.
TEST(DenseKernels, TransposedProductMatchesEigenForEverySizeAndStride) {
  std::mt19937 rng(3);
  for (int depth : {0, 1, 2, 6, 9, 11}) {
    for (int rows = 1; rows <= 10; ++rows) {
      for (int cols = 1; cols <= 10; ++cols) {
        // GIVEN x (depth x rows) and y (depth x cols) inside wider row-major buffers
        const RowMajor x = random_matrix(depth, rows + 3, rng), y = random_matrix(depth, cols + 2, rng);
        Eigen::MatrixXd out = Eigen::MatrixXd::Random(rows + 5, cols + 1);
        const Eigen::MatrixXd before = out;
        // WHEN out(1.., 0..) -= 2 x' y (columns 1.. of x, 2.. of y)
        add_transposed_product(depth, rows, cols, x.data() + 1, static_cast<int>(x.cols()), y.data() + 2,
                               static_cast<int>(y.cols()), out.data() + 1, static_cast<int>(out.rows()), -2.0, false);
        // THEN exactly that block changed, by the product
        Eigen::MatrixXd expected = before;
        expected.block(1, 0, rows, cols) -= 2.0 * x.block(0, 1, depth, rows).transpose() * y.block(0, 2, depth, cols);
        EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-13) << depth << " " << rows << " " << cols;
      }
    }
  }
}

TEST(DenseKernels, UpperProductFillsTheUpperTriangleAndNothingOutsideTheBlock) {
  std::mt19937 rng(4);
  for (int depth : {1, 8, 9}) {
    for (int n = 1; n <= 17; ++n) {
      // GIVEN x (depth x n) and an n x n block inside a larger matrix
      const RowMajor x = random_matrix(depth, n, rng);
      Eigen::MatrixXd out = Eigen::MatrixXd::Random(n + 2, n + 2);
      const Eigen::MatrixXd before = out;
      // WHEN the block's upper triangle gets x'x
      add_transposed_product(depth, n, n, x.data(), n, x.data(), n, out.data() + 1 + (n + 2), n + 2, 1.0, true);
      // THEN its upper triangle is exact, and only the block's lower triangle may differ elsewhere
      const Eigen::MatrixXd product = x.transpose() * x;
      for (int c = 0; c < n + 2; ++c) {
        for (int r = 0; r < n + 2; ++r) {
          const bool in_block = r >= 1 && r <= n && c >= 1 && c <= n;
          if (in_block && r <= c) {
            EXPECT_NEAR(out(r, c), before(r, c) + product(r - 1, c - 1), 1e-13);
          } else if (!in_block) {
            EXPECT_EQ(out(r, c), before(r, c));
          }
        }
      }
    }
  }
}

// The AVX2 kernel against the portable one: the same bits for every shape
// (each sum in the same order, no fused multiply-add), so the other tests,
// which run whichever this processor takes, hold for both.
TEST(DenseKernels, Avx2ProductGivesThePortableBits) {
#ifndef CDPR_AVX2_KERNELS
  GTEST_SKIP() << "not an x86-64 build";
#else
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this processor has no AVX2";
  std::mt19937 rng(7);
  int compared = 0;
  for (int depth : {0, 1, 3, 8, 9}) {
    for (int rows = 1; rows <= 17; ++rows) {
      for (int cols = 1; cols <= 17; ++cols) {
        for (bool upper : {false, true}) {
          if (upper && rows != cols) continue;
          const RowMajor x = random_matrix(depth, rows + 1, rng), y = random_matrix(depth, cols + 3, rng);
          const Eigen::MatrixXd start = Eigen::MatrixXd::Random(rows + 2, cols + 1);
          Eigen::MatrixXd portable = start, wide = start;
          add_transposed_product_portable(depth, rows, cols, x.data() + 1, rows + 1, y.data() + 3, cols + 3,
                                          portable.data() + 2, rows + 2, -0.5, upper);
          avx2::add_transposed_product(depth, rows, cols, x.data() + 1, rows + 1, y.data() + 3, cols + 3,
                                       wide.data() + 2, rows + 2, -0.5, upper);
          for (int c = 0; c < cols + 1; ++c) {
            for (int r = 0; r < rows + 2; ++r) {
              // the strictly lower triangle of an upper block is scratch
              if (upper && c >= 0 && c < cols && r >= 2 && r - 2 > c) continue;
              ASSERT_EQ(portable(r, c), wide(r, c)) << depth << " " << rows << " " << cols << " " << upper;
            }
          }
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 5 * (17 * 17 + 17));
#endif
}

TEST(DenseKernels, TransposedTimesVectorAddsXTransposeV) {
  std::mt19937 rng(5);
  for (int cols = 1; cols <= 19; ++cols) {  // blocks of eight columns, pairs and a single one
    const RowMajor x = random_matrix(7, cols + 1, rng);
    const Eigen::VectorXd v = Eigen::VectorXd::Random(7);
    Eigen::VectorXd out = Eigen::VectorXd::Random(cols);
    const Eigen::VectorXd expected = out - 3.0 * x.leftCols(cols).transpose() * v;
    add_transposed_times_vector(7, cols, x.data(), cols + 1, v.data(), -3.0, out.data());
    EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST(DenseKernels, SubtractTimesVectorSubtractsXV) {
  std::mt19937 rng(7);
  for (int cols = 0; cols <= 9; ++cols) {
    const RowMajor x = random_matrix(5, cols + 2, rng);
    const Eigen::VectorXd v = Eigen::VectorXd::Random(cols);
    Eigen::VectorXd out = Eigen::VectorXd::Random(5);
    const Eigen::VectorXd expected = out - x.leftCols(cols) * v;
    subtract_times_vector(5, cols, x.data(), cols + 2, v.data(), out.data());
    EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST(DenseKernels, RowWiseForwardSubstitutionSolvesUTransposedW) {
  std::mt19937 rng(6);
  for (int d : {1, 2, 6, 8}) {
    for (int m : {1, 2, 3, 8, 11, 16, 19}) {
      // GIVEN an upper triangular U with a strong diagonal and B (d x m)
      Eigen::MatrixXd u = Eigen::MatrixXd::Random(d, d).triangularView<Eigen::Upper>();
      u.diagonal().array() += 3.0;
      const RowMajor b = random_matrix(d, m, rng);
      RowMajor w(d, m);
      const Eigen::VectorXd inverse = u.diagonal().cwiseInverse();
      // WHEN W = U'^-1 B row by row
      solve_upper_transposed_rows(d, u.data(), inverse.data(), m, b.data(), w.data());
      // THEN U'W = B
      EXPECT_LT((u.transpose() * w - b).cwiseAbs().maxCoeff(), 1e-12) << d << " " << m;
    }
  }
}

// The other two AVX2 kernels against their portable versions, bit for bit.
TEST(DenseKernels, Avx2VectorProductAndSubstitutionGiveThePortableBits) {
#ifndef CDPR_AVX2_KERNELS
  GTEST_SKIP() << "not an x86-64 build";
#else
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this processor has no AVX2";
  std::mt19937 rng(8);
  for (int depth : {0, 1, 7, 9}) {
    for (int cols = 1; cols <= 37; ++cols) {  // blocks of sixteen, eight, quads and single columns
      const RowMajor x = random_matrix(depth, cols + 1, rng);
      const Eigen::VectorXd v = Eigen::VectorXd::Random(depth);
      const Eigen::VectorXd start = Eigen::VectorXd::Random(cols);
      Eigen::VectorXd portable = start, wide = start;
      add_transposed_times_vector_portable(depth, cols, x.data(), cols + 1, v.data(), -3.0, portable.data());
      avx2::add_transposed_times_vector(depth, cols, x.data(), cols + 1, v.data(), -3.0, wide.data());
      for (int c = 0; c < cols; ++c) ASSERT_EQ(portable(c), wide(c)) << depth << " " << cols;
    }
  }
  for (int d : {1, 2, 6, 8}) {
    for (int m = 1; m <= 29; ++m) {
      Eigen::MatrixXd u = Eigen::MatrixXd::Random(d, d).triangularView<Eigen::Upper>();
      u.diagonal().array() += 3.0;
      const Eigen::VectorXd inverse = u.diagonal().cwiseInverse();
      const RowMajor b = random_matrix(d, m, rng);
      RowMajor portable(d, m), wide(d, m);
      solve_upper_transposed_rows_portable(d, u.data(), inverse.data(), m, b.data(), portable.data());
      avx2::solve_upper_transposed_rows(d, u.data(), inverse.data(), m, b.data(), wide.data());
      for (int i = 0; i < d; ++i) {
        for (int q = 0; q < m; ++q) ASSERT_EQ(portable(i, q), wide(i, q)) << d << " " << m;
      }
    }
  }
#endif
}

TEST(DenseKernels, AllFiniteFindsAnInfinityOrNaNAnywhere) {
  using Check = bool (*)(const double*, std::size_t);
  std::vector<Check> checks = {all_finite, all_finite_portable};
#ifdef CDPR_AVX2_KERNELS
  if (__builtin_cpu_supports("avx2")) checks.push_back(avx2::all_finite);
#endif
  for (Check check : checks) {
    for (std::size_t n = 0; n <= 21; ++n) {
      std::vector<double> v(n, 1.5);
      EXPECT_TRUE(check(v.data(), n)) << n;
      for (std::size_t at = 0; at < n; ++at) {
        for (double bad : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN()}) {
          v[at] = bad;
          EXPECT_FALSE(check(v.data(), n)) << n << " " << at;
          v[at] = 1.5;
        }
      }
    }
  }
}

}  // namespace
}  // namespace cdpr
