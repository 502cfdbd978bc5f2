#include "bench_problems.h"

#include <cstdio>
#include <cstdlib>
#include <map>

#include "sim/dataset.h"

namespace cdpr::bench {

const BenchData& bench_data(int pose_count) {
  static std::map<int, BenchData> cache;
  auto found = cache.find(pose_count);
  if (found != cache.end()) return found->second;
  sim::DatasetConfig config;
  config.preset = sim::Preset::kLarge;
  config.pose_count = pose_count;
  config.seed = 7;
  config.anchor_perturbation_m = 10.0;
  auto dataset = sim::simulate_dataset(config);
  if (!dataset) {
    std::fprintf(stderr, "cdpr-bench: simulating %d poses failed: %s\n", pose_count, dataset.error().c_str());
    std::abort();
  }
  return cache.emplace(pose_count, BenchData{dataset->nominal, dataset->samples}).first->second;
}

BuiltProblem build_problem(const BenchData& data) {
  BuiltProblem built = build_calibration_problem(data.robot, data.samples, CalibrationOptions{});
  if (!built.problem) {
    std::fprintf(stderr, "cdpr-bench: problem refused: %s\n", built.message.c_str());
    std::abort();
  }
  return built;
}

SolverOptions our_options() {
  SolverOptions options;
  // Both solvers converge in 10-20 iterations on these problems; the cap only
  // bounds Ceres' iterative Schur, which does not converge at 9 and 35 poses
  // and would otherwise run to calibrate()'s 1000.
  options.max_iterations = kBenchMaxIterations;
  return options;
}

std::string to_string(CeresLinearSolver solver) {
  switch (solver) {
    case CeresLinearSolver::kSparseNormalCholesky: return "ceres_snc";
    case CeresLinearSolver::kSparseSchur: return "ceres_schur";
    case CeresLinearSolver::kDenseSchur: return "ceres_dense_schur";
    case CeresLinearSolver::kIterativeSchur: return "ceres_iter_schur";
    case CeresLinearSolver::kDenseNormalCholesky: return "ceres_dnc";
  }
  return "?";
}

ceres::Solver::Options ceres_options(CeresLinearSolver solver) {
  const SolverOptions ours = our_options();
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  switch (solver) {
    case CeresLinearSolver::kSparseNormalCholesky: options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY; break;
    case CeresLinearSolver::kSparseSchur: options.linear_solver_type = ceres::SPARSE_SCHUR; break;
    case CeresLinearSolver::kDenseSchur: options.linear_solver_type = ceres::DENSE_SCHUR; break;
    case CeresLinearSolver::kIterativeSchur:
      options.linear_solver_type = ceres::ITERATIVE_SCHUR;
      options.preconditioner_type = ceres::SCHUR_JACOBI;
      break;
    case CeresLinearSolver::kDenseNormalCholesky: options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY; break;
  }
  options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  options.dense_linear_algebra_library_type = ceres::EIGEN;
  options.function_tolerance = ours.function_tolerance;
  options.gradient_tolerance = ours.gradient_tolerance;
  options.parameter_tolerance = ours.parameter_tolerance;
  options.max_num_iterations = ours.max_iterations;
  options.initial_trust_region_radius = ours.initial_trust_radius;
  options.max_trust_region_radius = ours.max_trust_radius;
  options.min_trust_region_radius = ours.min_trust_radius;
  // Ours is single-threaded (solver/ has no threads), so Ceres gets one too.
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  return options;
}

}  // namespace cdpr::bench
