// End-to-end and solve-only timings, ours against Ceres, per pose count.
// Every run starts from the identical data-driven start (same data set, same
// build, or the saved start state restored) and records its time, iteration
// count and final cost for the summary table.

#include <time.h>

#include <iterator>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench_problems.h"
#include "solvers.h"
#include "summary.h"

namespace cdpr::bench {
namespace {

// Benchmark argument "solver": 0 ours, k > 0 Ceres with kCeresLinearSolvers[k - 1].
constexpr int kOurs = 0;
constexpr int kSolverCount = 1 + static_cast<int>(std::size(kCeresLinearSolvers));
CeresLinearSolver ceres_solver(int solver) { return kCeresLinearSolvers[solver - 1]; }

std::string series_name(int solver) { return solver == kOurs ? "ours" : to_string(ceres_solver(solver)); }

RunRecord solve_with(int solver, Problem& problem) {
  return solver == kOurs ? solve_ours(problem) : solve_ceres(problem, ceres_solver(solver));
}

// CPU time of the calling thread [s]. Both solvers run single-threaded in
// this thread, so on a shared machine it measures their work, not the
// scheduler's (wall time is what Google Benchmark's own "Time" column shows).
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void report(benchmark::State& state, const RunRecord& last) {
  state.counters["iterations"] = last.iterations;
  state.counters["final_cost"] = last.final_cost;
}

// Build problem + construct solver + solve.
void BM_EndToEnd(benchmark::State& state) {
  const int poses = static_cast<int>(state.range(0));
  const int solver = static_cast<int>(state.range(1));
  const BenchData& data = bench_data(poses);
  RunRecord run;
  for (auto _ : state) {
    const double start = thread_seconds();
    BuiltProblem built = build_problem(data);
    run = solve_with(solver, *built.problem);
    run.seconds = thread_seconds() - start;
    record(series_name(solver), "e2e", poses, run);
  }
  report(state, run);
  state.SetLabel(series_name(solver));
}

// calibrate() with default options: the robust fit's stages (Huber, and on
// clean data nothing more but the least-squares check), the covariance and
// the model-fit test included; compare with BM_EndToEnd of the Ceres
// configurations (which build and solve the least-squares problem alone).
void BM_Calibrate(benchmark::State& state) {
  const int poses = static_cast<int>(state.range(0));
  const BenchData& data = bench_data(poses);
  RunRecord run;
  for (auto _ : state) {
    const double start = thread_seconds();
    const CalibrationResult result = calibrate(data.robot, data.samples, CalibrationOptions{});
    run = {thread_seconds() - start, result.solver.iterations, result.solver.final_cost};
    record("calibrate", "e2e", poses, run);
  }
  report(state, run);
}

// Build problem only (build_calibration_problem: the data-driven start of
// every pose), the part both solvers' end-to-end runs share.
void BM_BuildProblem(benchmark::State& state) {
  const int poses = static_cast<int>(state.range(0));
  const BenchData& data = bench_data(poses);
  for (auto _ : state) {
    const double start = thread_seconds();
    BuiltProblem built = build_problem(data);
    benchmark::DoNotOptimize(built.problem.get());
    record("build", "e2e", poses, {thread_seconds() - start, 0, 0.0});
  }
}

// Construct solver + solve, the problem built once; the start state is
// restored before every run (a copy of a few thousand doubles).
void BM_Solve(benchmark::State& state) {
  const int poses = static_cast<int>(state.range(0));
  const int solver = static_cast<int>(state.range(1));
  BuiltProblem built = build_problem(bench_data(poses));
  const std::vector<double> start_state = built.problem->state();
  RunRecord run;
  for (auto _ : state) {
    const double start = thread_seconds();
    built.problem->state() = start_state;
    run = solve_with(solver, *built.problem);
    run.seconds = thread_seconds() - start;
    record(series_name(solver), "solve", poses, run);
  }
  report(state, run);
  state.SetLabel(series_name(solver));
}

void pose_counts_and_solvers(benchmark::internal::Benchmark* b) {
  for (int poses : {9, 35, 109, 1000}) {
    for (int solver = 0; solver < kSolverCount; ++solver) {
      // Dense Cholesky of the whole J^T J is cubic in the poses: small problems only.
      if (solver > 0 && ceres_solver(solver) == CeresLinearSolver::kDenseNormalCholesky && poses > 109) continue;
      b->Args({poses, solver});
    }
  }
  b->ArgNames({"poses", "solver"})->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_BuildProblem)->ArgName("poses")->Arg(9)->Arg(35)->Arg(109)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EndToEnd)->Apply(pose_counts_and_solvers);
BENCHMARK(BM_Calibrate)->ArgName("poses")->Arg(9)->Arg(35)->Arg(109)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Solve)->Apply(pose_counts_and_solvers);

}  // namespace
}  // namespace cdpr::bench
