#include "summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>
#include <vector>

namespace cdpr::bench {
namespace {

using SeriesKey = std::tuple<std::string, std::string, int>;  // series, phase, poses

std::map<SeriesKey, std::vector<RunRecord>>& records() {
  static std::map<SeriesKey, std::vector<RunRecord>> all;
  return all;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Stats {
  bool present = false;
  double ms = std::nan("");
  int iterations = 0;
  double final_cost = std::nan("");
};

Stats stats(const std::string& series, const std::string& phase, int poses) {
  const auto found = records().find({series, phase, poses});
  if (found == records().end() || found->second.empty()) return {};
  std::vector<double> seconds;
  for (const RunRecord& r : found->second) seconds.push_back(r.seconds);
  // Every run starts from the same state, so iterations and cost are the
  // same in all of them; the last one stands for all.
  const RunRecord& last = found->second.back();
  return {true, 1e3 * median(seconds), last.iterations, last.final_cost};
}

}  // namespace

void record(const std::string& series, const std::string& phase, int poses, const RunRecord& run) {
  records()[{series, phase, poses}].push_back(run);
}

void print_summary() {
  std::set<int> pose_counts;
  std::set<std::string> ceres_series;
  for (const auto& [key, runs] : records()) {
    pose_counts.insert(std::get<2>(key));
    if (std::get<0>(key).rfind("ceres_", 0) == 0) ceres_series.insert(std::get<0>(key));
  }
  if (pose_counts.empty()) return;

  std::printf("\nSummary (medians of all recorded runs, thread CPU time; Ceres single-threaded)\n");
  std::printf("%6s %-18s %6s %16s %10s %10s %10s %12s %12s\n", "poses", "solver", "iters", "final cost",
              "rel diff", "e2e ms", "solve ms", "ms/iter", "e2e ratio");
  std::vector<std::string> series = {"ours"};
  series.insert(series.end(), ceres_series.begin(), ceres_series.end());
  for (int poses : pose_counts) {
    const Stats ours = stats("ours", "e2e", poses);
    const Stats ours_solve = stats("ours", "solve", poses);
    std::string fastest;  // the Ceres configuration with the smallest end-to-end median
    double fastest_ms = std::nan("");
    for (const std::string& name : series) {
      const Stats e2e = stats(name, "e2e", poses);
      const Stats solve = stats(name, "solve", poses);
      if (!e2e.present && !solve.present) continue;
      const Stats& any = e2e.present ? e2e : solve;
      const Stats& reference = ours.present ? ours : ours_solve;
      const double rel_diff = std::abs(any.final_cost - reference.final_cost) /
                              std::max(std::abs(reference.final_cost), 1e-300);
      const double per_iteration = solve.present && solve.iterations > 0 ? solve.ms / solve.iterations : std::nan("");
      std::printf("%6d %-18s %6d %16.10e %10.2e %10.3f %10.3f %12.4f %11.2fx\n", poses, name.c_str(), any.iterations,
                  any.final_cost, rel_diff, e2e.ms, solve.ms, per_iteration, e2e.ms / ours.ms);
      if (name != "ours" && e2e.present && !(e2e.ms >= fastest_ms)) {
        fastest = name;
        fastest_ms = e2e.ms;
      }
    }
    if (!fastest.empty() && ours.present) {
      std::printf("%6d fastest Ceres end to end: %s, %.3f ms = %.2fx ours (%.3f ms)\n", poses, fastest.c_str(),
                  fastest_ms, fastest_ms / ours.ms, ours.ms);
    }
    // calibrate() runs the robust stages, the covariance and the model-fit
    // test besides the solve: what a user waits for, held to the same bar.
    const Stats calibrate = stats("calibrate", "e2e", poses);
    if (!fastest.empty() && calibrate.present) {
      std::printf("%6d calibrate() with defaults: %.3f ms, %d iterations; fastest Ceres end to end (%s) = %.2fx it\n",
                  poses, calibrate.ms, calibrate.iterations, fastest.c_str(), fastest_ms / calibrate.ms);
    }
  }
  for (int poses : pose_counts) {
    const Stats build = stats("build", "e2e", poses);
    if (build.present) std::printf("%6d build problem only (shared by all e2e runs): %.3f ms\n", poses, build.ms);
  }
  std::printf("rel diff: |cost - ours| / ours (must be < 1e-6); e2e ratio: this solver's / ours (e2e = build "
              "problem + construct solver + solve; solve = construct solver + solve)\n");
}

}  // namespace cdpr::bench
