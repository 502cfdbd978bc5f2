#pragma once
// The benchmark's problems: one simulated large-robot data set per pose
// count (catenary model, nominal anchors 10 m off), and the calibration's
// factor graph at its data-driven start, built exactly as calibrate() does.
// Both solvers start from the same state and stop at the same tolerances.

#include <string>
#include <vector>

#include <ceres/solver.h>

#include "solver/calibration/calibrate.h"
#include "solver/nls/levenberg_marquardt.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr::bench {

struct BenchData {
  Robot robot;  // nominal (robot.toml)
  std::vector<Sample> samples;
};

// Simulated once per pose count and cached (simulation is slow and not
// what is measured). Aborts with a message when the simulator fails.
const BenchData& bench_data(int pose_count);

// build_calibration_problem() with default CalibrationOptions; aborts when refused.
BuiltProblem build_problem(const BenchData& data);

// Our solver's options for the comparison: defaults, at most kBenchMaxIterations (both solvers).
inline constexpr int kBenchMaxIterations = 200;
SolverOptions our_options();

// Ceres' linear solvers worth trying on this problem (its best is what we
// compare against): SuiteSparse Cholesky of the whole J^T J; Schur
// elimination of the poses with the reduced system sparse (SuiteSparse) or
// dense (Eigen); conjugate gradients on the reduced system with the
// Schur-Jacobi preconditioner; dense Cholesky of the whole J^T J (small
// problems only).
enum class CeresLinearSolver { kSparseNormalCholesky, kSparseSchur, kDenseSchur, kIterativeSchur, kDenseNormalCholesky };
inline constexpr CeresLinearSolver kCeresLinearSolvers[] = {
    CeresLinearSolver::kSparseNormalCholesky, CeresLinearSolver::kSparseSchur, CeresLinearSolver::kDenseSchur,
    CeresLinearSolver::kIterativeSchur, CeresLinearSolver::kDenseNormalCholesky};
// "ceres_snc", "ceres_schur", "ceres_dense_schur", "ceres_iter_schur", "ceres_dnc".
std::string to_string(CeresLinearSolver solver);

// Ceres LM with our tolerances, initial radius and iteration cap, one thread.
ceres::Solver::Options ceres_options(CeresLinearSolver solver);

}  // namespace cdpr::bench
