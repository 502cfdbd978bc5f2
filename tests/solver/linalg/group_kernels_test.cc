// The per-group dense kernels of the Schur complement: compiled for a
// fixed group size (unrolled completely) they must give the bits of the
// runtime-size loops, and both the factor and the solutions they stand for.
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "solver/linalg/group_kernels.h"

namespace cdpr {
namespace {

using namespace group_kernels;

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// A random symmetric positive definite d x d matrix, column-major, and a
// right-hand side.
void random_system(int d, std::mt19937& rng, std::vector<double>& a, std::vector<double>& b) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::MatrixXd m(d, d);
  for (int i = 0; i < d * d; ++i) m(i) = value(rng);
  const Eigen::MatrixXd spd = m.transpose() * m + 0.5 * Eigen::MatrixXd::Identity(d, d);
  a.assign(spd.data(), spd.data() + d * d);
  b.resize(d);
  for (double& x : b) x = value(rng);
}

template <int D>
void expect_fixed_size_bits(std::mt19937& rng) {
  std::vector<double> a, b;
  random_system(D, rng, a, b);
  // GIVEN the same damped block factorised by both versions
  std::vector<double> fixed_u(D * D, 0.0), runtime_u(D * D, 0.0), fixed_inverse(D), runtime_inverse(D);
  ASSERT_TRUE(factor_group<D>(D, a.data(), fixed_u.data(), fixed_inverse.data(), 3.0, 1e-6, 1e32));
  ASSERT_TRUE(factor_group<0>(D, a.data(), runtime_u.data(), runtime_inverse.data(), 3.0, 1e-6, 1e32));
  // THEN the factors are the same bits, and U'U is the damped block
  EXPECT_TRUE(same_bits(fixed_u, runtime_u)) << "D = " << D;
  EXPECT_TRUE(same_bits(fixed_inverse, runtime_inverse)) << "D = " << D;
  Eigen::MatrixXd damped = Eigen::Map<const Eigen::MatrixXd>(a.data(), D, D);
  damped.diagonal() += damped.diagonal() / 3.0;
  const Eigen::MatrixXd u = Eigen::Map<const Eigen::MatrixXd>(fixed_u.data(), D, D).triangularView<Eigen::Upper>();
  EXPECT_LT((u.transpose() * u - damped).cwiseAbs().maxCoeff(), 1e-12);

  // AND both substitutions give the same bits, solving the damped system
  std::vector<double> fixed_x = b, runtime_x = b;
  solve_upper_transposed<D>(fixed_u.data(), fixed_inverse.data(), D, fixed_x.data());
  solve_upper_transposed<0>(runtime_u.data(), runtime_inverse.data(), D, runtime_x.data());
  EXPECT_TRUE(same_bits(fixed_x, runtime_x)) << "D = " << D;
  solve_upper<D>(fixed_u.data(), fixed_inverse.data(), D, fixed_x.data());
  solve_upper<0>(runtime_u.data(), runtime_inverse.data(), D, runtime_x.data());
  EXPECT_TRUE(same_bits(fixed_x, runtime_x)) << "D = " << D;
  const Eigen::VectorXd expected = damped.ldlt().solve(Eigen::Map<const Eigen::VectorXd>(b.data(), D));
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(fixed_x.data(), D) - expected).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(GroupKernels, FixedSizeKernelsGiveTheRuntimeSizeBits) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    expect_fixed_size_bits<8>(rng);
    expect_fixed_size_bits<6>(rng);
  }
}

TEST(GroupKernels, BothRefuseABlockThatIsNotPositiveDefinite) {
  // GIVEN an indefinite 8 x 8 block
  std::vector<double> a(64, 0.0), u(64), inverse(8);
  for (int j = 0; j < 8; ++j) a[j + 8 * j] = j == 5 ? -1.0 : 2.0;
  // THEN neither version factorises it, undamped
  const double infinity = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(factor_group<8>(8, a.data(), u.data(), inverse.data(), infinity, 1e-6, 1e32));
  EXPECT_FALSE(factor_group<0>(8, a.data(), u.data(), inverse.data(), infinity, 1e-6, 1e32));
}

}  // namespace
}  // namespace cdpr
