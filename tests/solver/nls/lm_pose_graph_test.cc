// LevenbergMarquardt on an SE(3) problem shaped like the calibration: poses
// with priors and relative-pose factors, cable ranges to global anchors and
// encoder offsets. Checked against the known truth (noise-free data) and a
// dense Gauss-Newton reference (noisy data).
#include <random>

#include <gtest/gtest.h>

#include "dense_gauss_newton.h"
#include "lm_test_factors.h"
#include "solver/nls/levenberg_marquardt.h"

namespace cdpr {
namespace {

constexpr int kCables = 4;
constexpr int kPoses = 12;

struct Truth {
  std::vector<Pose> poses;
  std::vector<Eigen::Vector3d> anchors, attachments;
  std::vector<double> offsets;
};

Truth make_truth() {
  Truth t;
  t.anchors = {{0, 0, 10}, {8, 0, 10.5}, {8, 6, 9.5}, {0, 6, 10}};
  t.attachments = {{-0.3, -0.2, 0.1}, {0.3, -0.2, 0.1}, {0.3, 0.2, 0.1}, {-0.3, 0.2, 0.1}};
  t.offsets = {0.5, -0.25, 1.0, 0.125};
  for (int k = 0; k < kPoses; ++k) {
    Pose p;
    p.position_world = Eigen::Vector3d(1.0 + 0.5 * k, 1.0 + 0.35 * (k % 5), 2.0 + 0.4 * (k % 3));
    p.world_R_platform = so3_exp(Eigen::Vector3d(0.05 * (k % 3), -0.04 * (k % 4), 0.1 * k));
    t.poses.push_back(p);
  }
  return t;
}

// Problem from measurements (truth + noise of the given scale), started off
// the truth by `start_error`.
Problem make_problem(const Truth& truth, double noise, double start_error) {
  std::mt19937 rng(42);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto noisy = [&](double sigma) { return noise * sigma * n01(rng); };
  auto nudge = [&]() -> Eigen::Vector3d { return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)) * start_error; };
  const double sigma_p = 0.01, sigma_r = 0.005, sigma_enc = 0.002;

  Problem problem;
  for (int k = 0; k < kPoses; ++k) {
    Pose start = truth.poses[k];
    start.position_world += nudge();
    start.world_R_platform = start.world_R_platform * so3_exp(nudge());
    problem.add_pose(PoseKey(k), start);
  }
  for (int i = 0; i < kCables; ++i) {
    problem.add_vector(AnchorKey(i), truth.anchors[i] + 10.0 * nudge());
    problem.add_vector(OffsetKey(i), Eigen::VectorXd::Constant(1, truth.offsets[i] + 10.0 * nudge()(0)));
  }
  for (int k = 0; k < kPoses; ++k) {
    Pose measured = truth.poses[k];
    measured.position_world += Eigen::Vector3d(noisy(sigma_p), noisy(sigma_p), noisy(sigma_p));
    measured.world_R_platform =
        measured.world_R_platform * so3_exp(Eigen::Vector3d(noisy(sigma_r), noisy(sigma_r), noisy(sigma_r)));
    problem.add_factor(std::make_unique<test::SE3PriorFactor>(PoseKey(k), measured, sigma_p, sigma_r));
    if (k > 0) {
      const Pose& a = truth.poses[k - 1];
      const Pose& b = truth.poses[k];
      Pose a_T_b;
      a_T_b.position_world = a.world_R_platform.conjugate() * (b.position_world - a.position_world) +
                             Eigen::Vector3d(noisy(sigma_p), noisy(sigma_p), noisy(sigma_p));
      a_T_b.world_R_platform = a.world_R_platform.conjugate() * b.world_R_platform;
      problem.add_factor(std::make_unique<test::SE3BetweenFactor>(PoseKey(k - 1), PoseKey(k), a_T_b, sigma_p, sigma_r));
    }
    for (int i = 0; i < kCables; ++i) {
      const double encoder = (truth.poses[k].transform(truth.attachments[i]) - truth.anchors[i]).norm() +
                             truth.offsets[i] + noisy(sigma_enc);
      problem.add_factor(std::make_unique<test::RangeFactor>(PoseKey(k), AnchorKey(i), OffsetKey(i),
                                                             truth.attachments[i], encoder, sigma_enc));
    }
  }
  return problem;
}

// Tolerances tight enough that LM stops at the minimum itself, not near it,
// so the comparison with the reference is about the minimum found.
SolverOptions tight() {
  SolverOptions o;
  o.function_tolerance = 1e-15;
  o.gradient_tolerance = 1e-9;
  o.parameter_tolerance = 1e-13;
  return o;
}

void expect_states_near(const Problem& a, const Problem& b, double tolerance) {
  ASSERT_EQ(a.state().size(), b.state().size());
  for (std::size_t v = 0; v < a.variables().size(); ++v) {
    const Key key = a.variables()[v].key;
    if (a.variables()[v].is_pose) {
      EXPECT_LT((a.pose(key).position_world - b.pose(key).position_world).norm(), tolerance) << to_string(key);
      EXPECT_LT(a.pose(key).world_R_platform.angularDistance(b.pose(key).world_R_platform), tolerance)
          << to_string(key);
    } else {
      EXPECT_LT((a.vector(key) - b.vector(key)).norm(), tolerance) << to_string(key);
    }
  }
}

TEST(LevenbergMarquardtPoseGraph, RecoversTheTruthFromNoiseFreeMeasurements) {
  // GIVEN noise-free measurements, a start 5 cm / 3 deg off per pose and 0.5 m off per anchor
  const Truth truth = make_truth();
  Problem problem = make_problem(truth, 0.0, 0.05);
  // WHEN solved
  const SolverSummary summary = LevenbergMarquardt(problem, {}).solve();
  // THEN every variable is back on the truth and the cost is zero
  ASSERT_EQ(summary.termination, TerminationType::kConverged) << summary.message;
  EXPECT_LT(summary.final_cost, 1e-12);
  for (int k = 0; k < kPoses; ++k) {
    EXPECT_LT((problem.pose(PoseKey(k)).position_world - truth.poses[k].position_world).norm(), 1e-8);
    EXPECT_LT(problem.pose(PoseKey(k)).world_R_platform.angularDistance(truth.poses[k].world_R_platform), 1e-8);
  }
  for (int i = 0; i < kCables; ++i) {
    EXPECT_LT((problem.vector(AnchorKey(i)) - truth.anchors[i]).norm(), 1e-7);
    EXPECT_NEAR(problem.vector(OffsetKey(i))(0), truth.offsets[i], 1e-7);
  }
}

TEST(LevenbergMarquardtPoseGraph, MatchesDenseGaussNewtonOnNoisyMeasurements) {
  // GIVEN noisy measurements (1 sigma) and the same start for LM and dense Gauss-Newton
  const Truth truth = make_truth();
  Problem lm_problem = make_problem(truth, 1.0, 0.02);
  Problem reference = make_problem(truth, 1.0, 0.02);
  // WHEN LM solves one and 30 dense Gauss-Newton steps the other
  const SolverSummary summary = LevenbergMarquardt(lm_problem, tight()).solve();
  test::dense_gauss_newton(reference, 30);
  // THEN they agree: same minimum, found through a different linear algebra path
  ASSERT_EQ(summary.termination, TerminationType::kConverged) << summary.message;
  EXPECT_GT(summary.final_cost, 1.0);  // the noise leaves a residual
  expect_states_near(lm_problem, reference, 1e-8);
}

TEST(LevenbergMarquardtPoseGraph, ConstantVariablesStayExactlyFixed) {
  // GIVEN anchor 2 and pose 5 held constant at values off the truth
  const Truth truth = make_truth();
  Problem problem = make_problem(truth, 1.0, 0.02);
  Problem reference = make_problem(truth, 1.0, 0.02);
  for (Problem* p : {&problem, &reference}) {
    p->set_constant(AnchorKey(2));
    p->set_constant(PoseKey(5));
  }
  const Eigen::VectorXd anchor_before = problem.vector(AnchorKey(2));
  const std::vector<double> pose_before(problem.state().begin() + problem.variables()[problem.variable_index(PoseKey(5))].ambient_offset,
                                        problem.state().begin() + problem.variables()[problem.variable_index(PoseKey(5))].ambient_offset + 7);
  // WHEN solved
  LevenbergMarquardt lm(problem, tight());
  const SolverSummary summary = lm.solve();
  test::dense_gauss_newton(reference, 30);
  // THEN they did not move by a bit, and the rest matches the reference with the same constants
  ASSERT_TRUE(summary.usable()) << summary.message;
  EXPECT_EQ(problem.vector(AnchorKey(2)), anchor_before);
  const int offset = problem.variables()[problem.variable_index(PoseKey(5))].ambient_offset;
  EXPECT_TRUE(std::equal(pose_before.begin(), pose_before.end(), problem.state().begin() + offset));
  expect_states_near(problem, reference, 1e-8);
}

}  // namespace
}  // namespace cdpr
