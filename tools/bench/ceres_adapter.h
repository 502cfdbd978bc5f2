#pragma once
// Benchmark only: the same factors and start as our solver, handed to Ceres
// (never linked into the daemon). Each of our factors becomes a Ceres cost
// function; poses get a manifold matching our right perturbation so both
// solvers take the same steps in the same coordinates.

#include <memory>
#include <vector>

#include <ceres/ceres.h>

#include "solver/nls/problem.h"

namespace cdpr::bench {

// Adds every variable and factor of `problem` to `ceres_problem`; the Ceres
// parameter blocks point into `problem.state()` (no copy), so solving with
// Ceres updates `problem` in place. `problem` must outlive `ceres_problem`.
void add_to_ceres(Problem& problem, ceres::Problem& ceres_problem);

// 0.5 * sum of squared residuals at the current state, evaluated by our factors.
double our_cost(const Problem& problem);

}  // namespace cdpr::bench
