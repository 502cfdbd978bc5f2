#include "solvers.h"

#include <ceres/problem.h>
#include <ceres/solver.h>

#include "ceres_adapter.h"

namespace cdpr::bench {

RunRecord solve_ours(Problem& problem) {
  LevenbergMarquardt lm(problem, our_options());
  const SolverSummary summary = lm.solve();
  return {0.0, summary.iterations, summary.final_cost};
}

RunRecord solve_ceres(Problem& problem, CeresLinearSolver linear_solver) {
  ceres::Problem ceres_problem;
  add_to_ceres(problem, ceres_problem);
  ceres::Solver::Summary summary;
  ceres::Solve(ceres_options(linear_solver), &ceres_problem, &summary);
  // Ceres counts iterations as accepted + rejected steps (its iterations[]
  // also holds iteration 0, the start); ours counts the same way.
  return {0.0, summary.num_successful_steps + summary.num_unsuccessful_steps, summary.final_cost};
}

}  // namespace cdpr::bench
