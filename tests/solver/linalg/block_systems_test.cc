// The linear systems of linalg on a block Jacobian written by hand: no
// problem, factor or key, only blocks and an elimination order. Both must
// give J^T J and J^T r of the dense Jacobian, and the Schur complement its
// solution.
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "solver/linalg/block_jacobian.h"
#include "solver/linalg/elimination_order.h"
#include "solver/linalg/normal_equations.h"
#include "solver/linalg/schur_complement.h"

namespace cdpr {
namespace {

// Variables 0 and 1 (2-dim) each in a group of its own, variable 2 (3-dim)
// kept, variable 3 constant; factor f reads {f, 2} for f < 2, the last one
// {2, 3}.
constexpr int kSlot = 1;

BlockJacobian make_jacobian() {
  BlockJacobian jacobian({2, 2, 3, 1}, {false, false, false, true});
  const std::vector<RowRange> rows3 = {{0, 3}, {0, 3}}, rows2 = {{0, 2}, {0, 2}};
  jacobian.add_factor(3, std::vector<int>{0, 2}, rows3);
  jacobian.add_factor(3, std::vector<int>{1, 2}, rows3);
  jacobian.add_factor(2, std::vector<int>{2, 3}, rows2);
  jacobian.allocate();
  return jacobian;
}

EliminationOrder make_order() {
  EliminationOrder order;
  order.group = {0, 1, EliminationOrder::kKept, EliminationOrder::kKept};
  order.group_count = 2;
  order.kept = {2};
  return order;
}

// Fills the slot with seeded values; returns the dense J (columns as the
// Jacobian's layout) and r.
void fill(BlockJacobian& jacobian, Eigen::MatrixXd& dense, Eigen::VectorXd& r) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  int rows = 0;
  for (int f = 0; f < jacobian.factor_count(); ++f) rows += jacobian.residual_dim(f);
  dense = Eigen::MatrixXd::Zero(rows, 7);
  r.resize(rows);
  int row = 0;
  for (int f = 0; f < jacobian.factor_count(); ++f) {
    const int m = jacobian.residual_dim(f);
    double* residual = jacobian.residuals(kSlot, f);
    for (int i = 0; i < m; ++i) residual[i] = r(row + i) = value(rng);
    for (int k = 0; k < jacobian.key_count(f); ++k) {
      double* block = jacobian.jacobian_blocks(kSlot, f)[k];
      if (block == nullptr) continue;
      const int d = jacobian.key_dim(f, k), column = jacobian.key_column(f, k);
      for (int i = 0; i < m; ++i) {
        for (int c = 0; c < d; ++c) block[i * d + c] = dense(row + i, column + c) = value(rng);
      }
    }
    row += m;
  }
}

TEST(BlockSystems, NormalEquationsAccumulateTheDenseProducts) {
  // GIVEN a block Jacobian and its normal equations
  BlockJacobian jacobian = make_jacobian();
  const NormalEquations equations(jacobian, make_order());
  Eigen::MatrixXd dense;
  Eigen::VectorXd r;
  fill(jacobian, dense, r);
  // WHEN J^T J and J^T r are accumulated
  ASSERT_EQ(equations.columns(), 7);
  std::vector<double> jtj(equations.nonzeros()), gradient(equations.columns());
  equations.accumulate(kSlot, jtj.data(), gradient.data());
  // THEN the upper triangle and the gradient are the dense ones; the
  // grouped variables come first, the constant one has no column
  EXPECT_EQ(equations.variable_column(0), 0);
  EXPECT_EQ(equations.variable_column(1), 2);
  EXPECT_EQ(equations.variable_column(2), 4);
  EXPECT_EQ(equations.variable_column(3), -1);
  const Eigen::MatrixXd expected = dense.transpose() * dense;
  Eigen::MatrixXd upper = Eigen::MatrixXd::Zero(7, 7);
  for (int c = 0; c < equations.columns(); ++c) {
    for (int p = equations.column_starts()[c]; p < equations.column_starts()[c + 1]; ++p) {
      upper(equations.row_indices()[p], c) = jtj[p];
    }
  }
  EXPECT_LT((Eigen::MatrixXd(upper.triangularView<Eigen::Upper>()) -
             Eigen::MatrixXd(expected.triangularView<Eigen::Upper>())).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(gradient.data(), 7) - dense.transpose() * r).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(BlockSystems, SchurComplementSolvesTheDenseSystem) {
  // GIVEN the same Jacobian with its groups eliminated first
  BlockJacobian jacobian = make_jacobian();
  const std::unique_ptr<SchurComplement> schur = SchurComplement::create(jacobian, make_order());
  ASSERT_NE(schur, nullptr);
  Eigen::MatrixXd dense;
  Eigen::VectorXd r;
  fill(jacobian, dense, r);
  // WHEN J^T J x = -J^T r is solved undamped
  std::vector<double> gradient(schur->columns());
  schur->accumulate(kSlot, gradient.data());
  std::string message;
  ASSERT_EQ(schur->factorize(std::numeric_limits<double>::infinity(), 1e-6, 1e32, &message),
            FactorizationStatus::kSuccess)
      << message;
  std::vector<double> x(schur->columns());
  for (int c = 0; c < schur->columns(); ++c) x[c] = -gradient[c];
  schur->solve(x.data(), x.data());
  // THEN x is the dense solution
  const Eigen::VectorXd expected = (dense.transpose() * dense).ldlt().solve(-dense.transpose() * r);
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(x.data(), 7) - expected).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(BlockSystems, SchurComplementRefusesAFactorReadingTwoGroups) {
  // GIVEN a factor that couples both groups
  BlockJacobian jacobian({2, 2, 3}, {false, false, false});
  const std::vector<RowRange> rows = {{0, 3}, {0, 3}, {0, 3}};
  jacobian.add_factor(3, std::vector<int>{0, 1, 2}, rows);
  jacobian.allocate();
  EliminationOrder order = make_order();
  order.group.pop_back();
  // THEN there is no Schur complement (the whole J^T J is the system)
  EXPECT_EQ(SchurComplement::create(jacobian, order), nullptr);
}

}  // namespace
}  // namespace cdpr
