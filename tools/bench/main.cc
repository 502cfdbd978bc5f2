// cdpr-bench: our sparse LM against Ceres on the same calibration problem
// (docs/benchmarks.md). Runs the Google Benchmark suite, median of 5 repetitions unless
// the command line says otherwise, then prints a summary table.
//
// Peak memory mode, for a separate process per solver:
//   cdpr-bench --peak-rss=ours|ceres_snc|ceres_schur|ceres_dense_schur|ceres_iter_schur|ceres_dnc [--poses=1000]
// simulates the data set, builds the problem, solves once and prints
// getrusage's ru_maxrss after building and after solving.

#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench_problems.h"
#include "solvers.h"
#include "summary.h"
#include "version/version.h"

namespace {

long max_rss_kib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;  // Linux: KiB
}

int peak_rss(const std::string& solver, int poses) {
  using namespace cdpr::bench;
  const BenchData& data = bench_data(poses);
  const long after_simulation = max_rss_kib();
  cdpr::BuiltProblem built = build_problem(data);
  const long after_build = max_rss_kib();
  RunRecord run;
  if (solver == "ours") {
    run = solve_ours(*built.problem);
  } else {
    bool known = false;
    for (CeresLinearSolver ceres : kCeresLinearSolvers) {
      if (solver != to_string(ceres)) continue;
      run = solve_ceres(*built.problem, ceres);
      known = true;
    }
    if (!known) {
      std::fprintf(stderr, "unknown solver '%s' (ours", solver.c_str());
      for (CeresLinearSolver ceres : kCeresLinearSolvers) std::fprintf(stderr, ", %s", to_string(ceres).c_str());
      std::fprintf(stderr, ")\n");
      return 2;
    }
  }
  const long after_solve = max_rss_kib();
  std::printf("%s poses=%d iterations=%d final_cost=%.10e peak_rss_kib: after_simulation=%ld after_build=%ld "
              "after_solve=%ld solve_added=%ld\n",
              solver.c_str(), poses, run.iterations, run.final_cost, after_simulation, after_build, after_solve,
              after_solve - after_build);
  return 0;
}

bool has_flag(const std::vector<char*>& args, const char* prefix) {
  for (char* a : args) {
    if (std::strncmp(a, prefix, std::strlen(prefix)) == 0) return true;
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> args(argv, argv + argc);
  if (has_flag(args, "--version")) {
    std::printf("%s\n", cdpr::version::version_text("cdpr-bench").c_str());
    return 0;
  }
  std::string peak_solver;
  int peak_poses = 1000;
  for (auto it = args.begin() + 1; it != args.end();) {
    if (std::strncmp(*it, "--peak-rss=", 11) == 0) {
      peak_solver = *it + 11;
      it = args.erase(it);
    } else if (std::strncmp(*it, "--poses=", 8) == 0) {
      peak_poses = std::atoi(*it + 8);
      it = args.erase(it);
    } else {
      ++it;
    }
  }
  if (!peak_solver.empty()) return peak_rss(peak_solver, peak_poses);

  // Shared, noisy machine: medians of repeated runs by default.
  static char repetitions[] = "--benchmark_repetitions=5";
  static char aggregates[] = "--benchmark_report_aggregates_only=true";
  if (!has_flag(args, "--benchmark_repetitions")) args.push_back(repetitions);
  if (!has_flag(args, "--benchmark_report_aggregates_only") && !has_flag(args, "--benchmark_display_aggregates_only")) {
    args.push_back(aggregates);
  }
  int count = static_cast<int>(args.size());
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  cdpr::bench::print_summary();
  return 0;
}
