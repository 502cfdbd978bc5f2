#pragma once
// What the benchmark loops record per run (wall time, iterations, final
// cost), and the compact side-by-side table printed after all benchmarks,
// outside the timing loops. Medians over every recorded run, so the table
// and Google Benchmark's median aggregates describe the same runs.

#include <string>

namespace cdpr::bench {

struct RunRecord {
  double seconds = 0.0;
  int iterations = 0;     // LM iterations, accepted and rejected
  double final_cost = 0.0;
};

// series: "ours" or a Ceres configuration ("ceres_snc", ...); phase: "e2e" (build problem +
// construct solver + solve) or "solve" (construct solver + solve from the
// same start, problem already built).
void record(const std::string& series, const std::string& phase, int poses, const RunRecord& run);

void print_summary();

}  // namespace cdpr::bench
