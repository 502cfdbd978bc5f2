// LevenbergMarquardt with the per-pose blocks eliminated (Schur complement,
// solver/linalg/schur_complement.h) against the whole J^T J: same iterations, same
// solution, same covariance; and when the elimination is (not) chosen.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "dense_gauss_newton.h"
#include "lm_test_factors.h"
#include "solver/nls/levenberg_marquardt.h"

namespace cdpr {
namespace {

const std::array<Eigen::Vector3d, 4> kAnchors = {Eigen::Vector3d(0, 0, 20), Eigen::Vector3d(30, 0, 21),
                                                 Eigen::Vector3d(30, 25, 19), Eigen::Vector3d(0, 25, 20)};
const std::array<Eigen::Vector3d, 4> kAttachments = {
    Eigen::Vector3d(-0.4, -0.3, 0.2), Eigen::Vector3d(0.4, -0.3, 0.2), Eigen::Vector3d(0.4, 0.3, 0.2),
    Eigen::Vector3d(-0.4, 0.3, 0.2)};

// How the ranges reach the global variables: cable i through AnchorKey(i)
// and OffsetKey(i); or each pose without one cable (k % 4), so its global
// columns are not contiguous (the block-pair path of SchurComplement); or
// cable i with OffsetKey((i + 1) % 4), so a range's own global columns have
// gaps (its gathered Jacobian holds zero columns); or a pose's four cables
// in one factor, read three times each, whose anchors and offsets each
// reach their cable's rows alone (its J^T J summed over runs of columns and
// their rows).
enum class Wiring { kDirect, kOneCableMissingPerPose, kCrossedOffsets, kStacked };

// A calibration-shaped graph: per pose a prior and four ranges to the
// global anchors and offsets, started off the truth; `link_poses` adds
// relative-pose factors that couple consecutive poses.
Problem calibration_like(int poses, bool link_poses, Wiring wiring = Wiring::kDirect) {
  Problem problem;
  std::vector<Pose> truth;
  for (int k = 0; k < poses; ++k) {
    Pose p;
    p.position_world = Eigen::Vector3d(5 + 2.0 * (k % 10), 4 + 1.7 * (k / 10), 3 + 0.3 * (k % 7));
    p.world_R_platform = so3_exp(Eigen::Vector3d(0.02 * (k % 5), -0.03 * (k % 3), 0.01 * k));
    truth.push_back(p);
    Pose start = p;
    start.position_world += Eigen::Vector3d(0.03, -0.02, 0.04);
    start.world_R_platform = start.world_R_platform * so3_exp(Eigen::Vector3d(0.01, 0.02, -0.01));
    problem.add_pose(PoseKey(k), start);
  }
  for (int i = 0; i < 4; ++i) {
    problem.add_vector(AnchorKey(i), kAnchors[i] + Eigen::Vector3d(0.5, -0.4, 0.3));
    problem.add_vector(OffsetKey(i), Eigen::VectorXd::Constant(1, 0.2 * i));
  }
  for (int k = 0; k < poses; ++k) {
    problem.add_factor(std::make_unique<test::SE3PriorFactor>(PoseKey(k), truth[k], 0.01, 0.005));
    if (wiring == Wiring::kStacked) {
      std::array<double, 12> encoders;
      for (int row = 0; row < 12; ++row) {
        const int i = row / 3;
        encoders[row] = (truth[k].transform(kAttachments[i]) - kAnchors[i]).norm() + 0.1 * i + 0.001 * (row % 3);
      }
      problem.add_factor(std::make_unique<test::StackedRangesFactor<3>>(k, kAttachments, encoders, 0.002, Loss{3.0}));
      continue;
    }
    for (int i = 0; i < 4; ++i) {
      if (wiring == Wiring::kOneCableMissingPerPose && i == k % 4) continue;
      const int offset = wiring == Wiring::kCrossedOffsets ? (i + 1) % 4 : i;
      const double encoder =
          (truth[k].transform(kAttachments[i]) - kAnchors[i]).norm() + 0.1 * offset + 0.001 * (k % 3);
      problem.add_factor(std::make_unique<test::RangeFactor>(PoseKey(k), AnchorKey(i), OffsetKey(offset),
                                                             kAttachments[i], encoder, 0.002, Loss{3.0}));
    }
    if (link_poses && k > 0) {
      Pose a_T_b;
      a_T_b.position_world =
          truth[k - 1].world_R_platform.conjugate() * (truth[k].position_world - truth[k - 1].position_world);
      a_T_b.world_R_platform = truth[k - 1].world_R_platform.conjugate() * truth[k].world_R_platform;
      problem.add_factor(std::make_unique<test::SE3BetweenFactor>(PoseKey(k - 1), PoseKey(k), a_T_b, 0.01, 0.005));
    }
  }
  return problem;
}

SolverOptions with_elimination(bool eliminate) {
  SolverOptions options;
  options.eliminate_poses = eliminate;
  return options;
}

TEST(LevenbergMarquardtSchur, EliminatesPosesOnlyWhenNoFactorCouplesTwoPoses) {
  Problem independent = calibration_like(12, false), linked = calibration_like(12, true);
  EXPECT_EQ(LevenbergMarquardt(independent, {}).linear_system(), LinearSystemKind::kPosesEliminated);
  EXPECT_EQ(LevenbergMarquardt(independent, with_elimination(false)).linear_system(), LinearSystemKind::kFull);
  EXPECT_EQ(LevenbergMarquardt(linked, {}).linear_system(), LinearSystemKind::kFull);
  // nothing global to reduce to: the whole system
  Problem poses_only;
  poses_only.add_pose(PoseKey(0), Pose{});
  poses_only.add_factor(std::make_unique<test::SE3PriorFactor>(PoseKey(0), Pose{}, 0.01, 0.005));
  EXPECT_EQ(LevenbergMarquardt(poses_only, {}).linear_system(), LinearSystemKind::kFull);
}

class LevenbergMarquardtSchurWiring : public ::testing::TestWithParam<Wiring> {};

TEST_P(LevenbergMarquardtSchurWiring, TakesTheSameStepsAsTheWholeSystem) {
  // GIVEN the same problem twice, one solved with the poses eliminated, one on the whole J^T J
  Problem reduced = calibration_like(30, false, GetParam()), full = calibration_like(30, false, GetParam());
  std::vector<IterationSummary> reduced_progress, full_progress;
  SolverOptions reduced_options = with_elimination(true), full_options = with_elimination(false);
  reduced_options.progress = [&](const IterationSummary& s) { reduced_progress.push_back(s); };
  full_options.progress = [&](const IterationSummary& s) { full_progress.push_back(s); };
  LevenbergMarquardt reduced_lm(reduced, reduced_options), full_lm(full, full_options);
  // WHEN solved
  const SolverSummary a = reduced_lm.solve(), b = full_lm.solve();
  // THEN they take the same steps until the cost changes by no more than
  // rounding (there the two sums of the same numbers may accept or refuse
  // the last tiny steps differently), and end at the same solution with the
  // same covariance
  ASSERT_TRUE(a.usable()) << a.message;
  ASSERT_TRUE(b.usable()) << b.message;
  int compared = 0;
  for (std::size_t i = 0; i < std::min(reduced_progress.size(), full_progress.size()); ++i) {
    if (std::abs(full_progress[i].cost - b.final_cost) <= 1e-9 * b.final_cost) break;
    EXPECT_NEAR(reduced_progress[i].cost, full_progress[i].cost, 1e-9 * (1.0 + full_progress[i].cost)) << i;
    EXPECT_EQ(reduced_progress[i].step_accepted, full_progress[i].step_accepted) << i;
    EXPECT_NEAR(reduced_progress[i].step_norm, full_progress[i].step_norm, 1e-9 * (1.0 + full_progress[i].step_norm));
    ++compared;
  }
  EXPECT_GE(compared, 5);
  // Both stop at the first step that changes the cost by less than the
  // function tolerance (1e-10 relative), so where rounding ends them may
  // differ by about that much.
  EXPECT_NEAR(a.final_cost, b.final_cost, SolverOptions{}.function_tolerance * b.final_cost);
  for (std::size_t i = 0; i < full.state().size(); ++i) EXPECT_NEAR(reduced.state()[i], full.state()[i], 1e-6) << i;
  const std::vector<Key> keys = {AnchorKey(2), OffsetKey(2), PoseKey(7)};
  const Eigen::MatrixXd ca = reduced_lm.covariance(keys), cb = full_lm.covariance(keys);
  ASSERT_EQ(ca.rows(), 10);
  ASSERT_EQ(cb.rows(), 10);
  EXPECT_LT((ca - cb).norm(), 1e-6 * cb.norm());
}

INSTANTIATE_TEST_SUITE_P(, LevenbergMarquardtSchurWiring,
                         ::testing::Values(Wiring::kDirect, Wiring::kOneCableMissingPerPose, Wiring::kCrossedOffsets,
                                           Wiring::kStacked));

TEST(LevenbergMarquardtSchur, CovarianceIsTheDenseInverseOfTheInformationMatrix) {
  // GIVEN a solved calibration-shaped problem with the poses eliminated
  Problem problem = calibration_like(10, false);
  LevenbergMarquardt lm(problem, {});
  ASSERT_EQ(lm.linear_system(), LinearSystemKind::kPosesEliminated);
  ASSERT_TRUE(lm.solve().usable());
  // WHEN asking for a global and a per-pose variable together
  const Eigen::MatrixXd covariance = lm.covariance({AnchorKey(1), PoseKey(3)});
  // THEN it is that block of the dense (J^T J)^-1
  const test::DenseLinearisation lin = test::linearise_dense(problem);
  const Eigen::MatrixXd full = (lin.jacobian.transpose() * lin.jacobian).inverse();
  const int anchor = lin.column[problem.variable_index(AnchorKey(1))];
  const int pose = lin.column[problem.variable_index(PoseKey(3))];
  Eigen::MatrixXd expected(9, 9);
  const int starts[2] = {anchor, pose}, dims[2] = {3, 6};
  for (int a = 0, ra = 0; a < 2; ra += dims[a++]) {
    for (int b = 0, rb = 0; b < 2; rb += dims[b++]) {
      expected.block(ra, rb, dims[a], dims[b]) = full.block(starts[a], starts[b], dims[a], dims[b]);
    }
  }
  ASSERT_EQ(covariance.rows(), 9);
  EXPECT_LT((covariance - expected).norm(), 1e-9 * expected.norm());
}

TEST(LevenbergMarquardtSchur, TheLastLinearisationGivesTheSameCovarianceBits) {
  // GIVEN a solved calibration-shaped problem with the poses eliminated
  Problem problem = calibration_like(10, false);
  LevenbergMarquardt lm(problem, {});
  ASSERT_TRUE(lm.solve().usable());
  // WHEN the covariance of global variables is asked with the factors
  // evaluated again, then from the last linearisation, then with a pose
  // among them (the whole system solved, not only the reduced one)
  const std::vector<Key> globals = {AnchorKey(0), OffsetKey(0), AnchorKey(2)};
  const Eigen::MatrixXd evaluated = lm.covariance(globals);
  lm.reuse_last_linearization();
  const Eigen::MatrixXd reused = lm.covariance(globals);
  const Eigen::MatrixXd with_pose = lm.covariance({AnchorKey(0), OffsetKey(0), AnchorKey(2), PoseKey(3)});
  // THEN the globals' block is the same to the bit each time
  ASSERT_EQ(evaluated.rows(), 7);
  EXPECT_EQ(std::memcmp(evaluated.data(), reused.data(), sizeof(double) * evaluated.size()), 0);
  const Eigen::MatrixXd block = with_pose.topLeftCorner(7, 7);
  EXPECT_EQ(std::memcmp(evaluated.data(), block.data(), sizeof(double) * evaluated.size()), 0);
}

TEST(LevenbergMarquardtSchur, ASolveFromTheLastLinearisationTakesTheSameSteps) {
  // GIVEN a problem solved for two iterations, then solved on, the
  // second solve evaluating its start again or taking the last
  // linearisation; and one whose values were moved before that
  auto second_solve = [](bool reuse, bool move) {
    Problem problem = calibration_like(10, false);
    SolverOptions options;
    options.max_iterations = 2;
    LevenbergMarquardt lm(problem, options);
    lm.solve();
    if (move) problem.state()[0] += 1e-3;
    lm.set_max_iterations(100);
    if (reuse) lm.reuse_last_linearization();
    const SolverSummary summary = lm.solve();
    return std::make_tuple(summary.iterations, summary.initial_cost, summary.final_cost, problem.state());
  };
  // THEN the iterations, costs and values are the same to the bit (values
  // moved since are evaluated anyway)
  EXPECT_EQ(second_solve(true, false), second_solve(false, false));
  EXPECT_EQ(second_solve(true, true), second_solve(false, true));
}

}  // namespace
}  // namespace cdpr
