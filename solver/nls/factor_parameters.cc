#include "solver/nls/factor_parameters.h"

namespace cdpr {

std::vector<const double*> parameter_blocks(const Problem& problem, const Factor& factor) {
  std::vector<const double*> blocks;
  for (const Key& key : factor.keys()) {
    blocks.push_back(problem.state().data() + problem.variables()[problem.variable_index(key)].ambient_offset);
  }
  return blocks;
}

}  // namespace cdpr
