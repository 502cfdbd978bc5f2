// The solver's kernels on the 35-pose problem: one factor evaluation, one
// numeric refactorisation, one covariance extraction.

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench_problems.h"
#include "solver/linalg/normal_equations.h"
#include "solver/linalg/schur_complement.h"
#include "solver/linalg/sparse_cholesky.h"
#include "solver/nls/keys.h"
#include "solver/nls/linearization.h"
#include "solver/calibration/static_pose_factor.h"

namespace cdpr::bench {
namespace {

constexpr int kKernelPoses = 35;

// One StaticPoseFactor::evaluate with all Jacobians, at the start state.
void BM_StaticPoseFactorEvaluate(benchmark::State& state) {
  BuiltProblem built = build_problem(bench_data(kKernelPoses));
  const Problem& problem = *built.problem;
  const Factor* factor = nullptr;
  for (const auto& f : problem.factors()) {
    if (dynamic_cast<const StaticPoseFactor*>(f.get()) != nullptr) {
      factor = f.get();
      break;
    }
  }
  if (factor == nullptr) {
    state.SkipWithError("no StaticPoseFactor in the problem");
    return;
  }
  std::vector<const double*> parameters;
  std::vector<std::vector<double>> jacobian_storage;
  std::vector<double*> jacobians;
  for (const Key& key : factor->keys()) {
    const Problem::Variable& v = problem.variables()[problem.variable_index(key)];
    parameters.push_back(problem.state().data() + v.ambient_offset);
    jacobian_storage.emplace_back(factor->residual_dim() * v.tangent_dim);
  }
  for (auto& j : jacobian_storage) jacobians.push_back(j.data());
  std::vector<double> residual(factor->residual_dim());
  double cost = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(factor->evaluate(parameters.data(), residual.data(), jacobians.data(), &cost));
    benchmark::ClobberMemory();
  }
}

// SparseCholesky::factorize of the whole damped J^T J at the start, in
// NormalEquations' pattern, on a SparseCholesky constructed like the
// solver's full system: the numeric refactorisation of one LM iteration on
// problems whose poses cannot be eliminated (the calibration's own graph
// takes BM_SchurRefactorisation's path). Symbolic analysis outside the loop.
void BM_NumericRefactorisation(benchmark::State& state) {
  BuiltProblem built = build_problem(bench_data(kKernelPoses));
  Linearization linearization(*built.problem);
  NormalEquations normal(linearization.jacobian(), built.problem->elimination_order());
  double cost = 0.0;
  int failed = -1;
  if (!linearization.evaluate(built.problem->state().data(), 0, &cost, &failed)) {
    state.SkipWithError("factor not evaluable at the start");
    return;
  }
  std::vector<double> jtj(normal.nonzeros()), gradient(normal.columns());
  normal.accumulate(0, jtj.data(), gradient.data());
  // The LM's damping at its initial radius 1e4: D / radius, D = diag clamped.
  const double radius = our_options().initial_trust_radius;
  for (int c = 0; c < normal.columns(); ++c) {
    double& d = jtj[normal.diagonal(c)];
    d += std::clamp(d, 1e-6, 1e32) / radius;
  }
  SparseCholesky cholesky(normal.columns(), normal.column_starts(), normal.row_indices());
  std::string message;
  for (auto _ : state) {
    benchmark::DoNotOptimize(cholesky.factorize(jtj.data(), &message));
  }
  state.counters["columns"] = normal.columns();
  state.counters["nonzeros"] = normal.nonzeros();
}

// The refactorisation our solver does per iteration on a calibration
// problem: the per-pose blocks damped, Cholesky-factorised and eliminated
// (Schur complement), and the dense Cholesky factorisation of the reduced
// matrix over the 16 global columns; at the start, damping of radius 1e4.
// Per pose count, to show it grows linearly.
void BM_SchurRefactorisation(benchmark::State& state) {
  BuiltProblem built = build_problem(bench_data(static_cast<int>(state.range(0))));
  Linearization linearization(*built.problem);
  std::unique_ptr<SchurComplement> schur =
      SchurComplement::create(linearization.jacobian(), built.problem->elimination_order());
  if (!schur) {
    state.SkipWithError("the calibration problem has no per-pose structure");
    return;
  }
  double cost = 0.0;
  int failed = -1;
  if (!linearization.evaluate(built.problem->state().data(), 0, &cost, &failed)) {
    state.SkipWithError("factor not evaluable at the start");
    return;
  }
  std::vector<double> gradient(schur->columns());
  schur->accumulate(0, gradient.data());
  const double radius = our_options().initial_trust_radius;
  std::string message;
  for (auto _ : state) {
    benchmark::DoNotOptimize(schur->factorize(radius, 1e-6, 1e32, &message));
  }
  state.counters["columns"] = schur->columns();
}

// LevenbergMarquardt::covariance of the 4 anchors and 4 offsets (16
// tangent dimensions) at the solution.
void BM_Covariance(benchmark::State& state) {
  BuiltProblem built = build_problem(bench_data(kKernelPoses));
  LevenbergMarquardt lm(*built.problem, our_options());
  lm.solve();
  std::vector<Key> keys;
  for (int i = 0; i < kCableCount; ++i) keys.push_back(AnchorKey(i));
  for (int i = 0; i < kCableCount; ++i) keys.push_back(OffsetKey(i));
  for (auto _ : state) {
    benchmark::DoNotOptimize(lm.covariance(keys));
  }
}

// Our solver's construction alone (pattern of J^T J, symbolic analysis,
// scratch): the setup part of BM_Solve, per pose count.
void BM_ConstructOurSolver(benchmark::State& state) {
  BuiltProblem built = build_problem(bench_data(static_cast<int>(state.range(0))));
  for (auto _ : state) {
    LevenbergMarquardt lm(*built.problem, our_options());
    benchmark::DoNotOptimize(&lm);
  }
}

BENCHMARK(BM_ConstructOurSolver)->ArgName("poses")->Arg(35)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StaticPoseFactorEvaluate)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_NumericRefactorisation)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SchurRefactorisation)->ArgName("poses")->Arg(35)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Covariance)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cdpr::bench
