#include "solver/linalg/sparse_cholesky.h"

#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

namespace cdpr {
namespace {

// Upper-triangle CSC of a dense symmetric matrix, keeping the entries of `mask`.
struct Upper {
  std::vector<int> starts, rows;
  std::vector<double> values;
};
Upper upper_of(const Eigen::MatrixXd& a, const Eigen::MatrixXi& mask) {
  Upper u;
  u.starts.push_back(0);
  for (int c = 0; c < a.cols(); ++c) {
    for (int r = 0; r <= c; ++r) {
      if (r != c && !mask(r, c)) continue;
      u.rows.push_back(r);
      u.values.push_back(a(r, c));
    }
    u.starts.push_back(static_cast<int>(u.rows.size()));
  }
  return u;
}

// A random sparse symmetric pattern (arrow plus scattered entries) and an
// SPD matrix on it (diagonally dominant).
struct SpdCase {
  Eigen::MatrixXd a;
  Eigen::MatrixXi mask;
};
SpdCase random_spd(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::bernoulli_distribution keep(0.15);
  SpdCase s{Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXi::Zero(n, n)};
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < c; ++r) {
      if (keep(rng) || c >= n - 3) {  // the last 3 columns are dense: global variables
        s.mask(r, c) = s.mask(c, r) = 1;
        s.a(r, c) = s.a(c, r) = u(rng);
      }
    }
  }
  for (int c = 0; c < n; ++c) s.a(c, c) = s.a.row(c).cwiseAbs().sum() + 0.5 + std::abs(u(rng));
  return s;
}

TEST(SparseCholesky, SolvesRandomSpdSystemsLikeDenseLlt) {
  std::mt19937 rng(7);
  for (int n : {1, 5, 40, 120}) {
    // GIVEN a random sparse SPD matrix and right-hand side
    const auto [a, mask] = random_spd(n, rng);
    const Upper u = upper_of(a, mask);
    Eigen::VectorXd b = Eigen::VectorXd::Random(n);
    SparseCholesky cholesky(n, u.starts, u.rows);
    EXPECT_EQ(cholesky.size(), n);
    EXPECT_EQ(cholesky.nonzeros(), static_cast<int>(u.values.size()));
    // WHEN factorised and solved
    std::string message;
    ASSERT_EQ(cholesky.factorize(u.values.data(), &message), FactorizationStatus::kSuccess) << message;
    Eigen::VectorXd x(n);
    cholesky.solve(b.data(), x.data());
    // THEN the solution matches Eigen's dense LLT
    const Eigen::VectorXd expected = a.llt().solve(b);
    EXPECT_LT((x - expected).norm(), 1e-11 * expected.norm()) << n;
  }
}

TEST(SparseCholesky, RefactorisesNewValuesOnTheSamePattern) {
  // GIVEN one pattern and two value sets, and an aliasing solve (x == b)
  std::mt19937 rng(8);
  const auto [a, mask] = random_spd(30, rng);
  SparseCholesky cholesky(30, upper_of(a, mask).starts, upper_of(a, mask).rows);
  for (double shift : {0.0, 10.0}) {
    const Eigen::MatrixXd shifted = a + shift * Eigen::MatrixXd::Identity(30, 30);
    const Upper u = upper_of(shifted, mask);
    ASSERT_EQ(cholesky.factorize(u.values.data(), nullptr), FactorizationStatus::kSuccess);
    Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(30, -1.0, 1.0);
    const Eigen::VectorXd expected = shifted.llt().solve(x);
    cholesky.solve(x.data(), x.data());
    // THEN each factorisation solves its own matrix
    EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm()) << shift;
  }
}

TEST(SparseCholesky, ReportsIndefiniteMatrixAsNotPositiveDefinite) {
  // GIVEN a symmetric indefinite matrix (one negative eigenvalue)
  std::mt19937 rng(9);
  auto [a, mask] = random_spd(20, rng);
  a(11, 11) = -a(11, 11);
  const Upper u = upper_of(a, mask);
  SparseCholesky cholesky(20, u.starts, u.rows);
  // WHEN factorised
  std::string message;
  const FactorizationStatus status = cholesky.factorize(u.values.data(), &message);
  // THEN it says so, with a message, and a later SPD matrix still factorises
  EXPECT_EQ(status, FactorizationStatus::kNotPositiveDefinite);
  EXPECT_NE(message.find("not positive definite"), std::string::npos) << message;
  a(11, 11) = -a(11, 11);
  const Upper good = upper_of(a, mask);
  EXPECT_EQ(cholesky.factorize(good.values.data(), nullptr), FactorizationStatus::kSuccess);
}

TEST(SparseCholesky, ReportsNonFiniteEntriesAsFatal) {
  // GIVEN a matrix with a NaN entry; THEN factorize refuses it as fatal
  SparseCholesky cholesky(2, {0, 1, 3}, {0, 0, 1});
  const double values[3] = {2.0, std::nan(""), 3.0};
  std::string message;
  EXPECT_EQ(cholesky.factorize(values, &message), FactorizationStatus::kFatal);
  EXPECT_FALSE(message.empty());
}

}  // namespace
}  // namespace cdpr
