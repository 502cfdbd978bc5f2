#pragma once
// The ambient storage of a factor's variables inside a Problem, in the
// factor's keys() order: what Factor::evaluate() takes as `parameters`, for
// evaluating a factor outside the solver (reports, held-out predictions).

#include <vector>

#include "solver/nls/factor.h"
#include "solver/nls/problem.h"

namespace cdpr {

// Every key of `factor` must exist in `problem`; the pointers are valid until
// the problem's structure changes.
std::vector<const double*> parameter_blocks(const Problem& problem, const Factor& factor);

}  // namespace cdpr
