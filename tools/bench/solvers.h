#pragma once
// One solve of an already built problem by each solver, from the problem's
// current state (which it leaves at the solution): ours constructs a
// LevenbergMarquardt (pattern, symbolic analysis, scratch) and solves; Ceres
// builds a ceres::Problem over the same factors and state and solves.

#include "bench_problems.h"
#include "solver/nls/problem.h"
#include "summary.h"

namespace cdpr::bench {

// seconds is left 0: the callers time what they mean to time.
RunRecord solve_ours(Problem& problem);
RunRecord solve_ceres(Problem& problem, CeresLinearSolver linear_solver);

}  // namespace cdpr::bench
