#pragma once
// Which variables a linear system eliminates first, as the problem gives it
// (Ceres' ParameterBlockOrdering in spirit). Variables of one group are
// eliminated together, before everything else; a group is small and no
// factor reads two groups' variables (then its block of J^T J is dense and
// the others are zero: SchurComplement). The kept variables form the
// reduced system, their columns in `kept` order. Indices are the variables'
// (BlockJacobian's); constant variables take no part.

#include <vector>

namespace cdpr {

struct EliminationOrder {
  static constexpr int kKept = -1;
  // Per variable: its group, 0 ... group_count - 1, or kKept.
  std::vector<int> group;
  int group_count = 0;
  // The kept non-constant variables in the order of their columns.
  std::vector<int> kept;
};

}  // namespace cdpr
