#pragma once
// Which of two models predicts the same held-out poses better (solver/
// diagnosis.h): the per-pose drops d_j = chi2_j(current) - chi2_j(candidate),
// paired by sample id over the poses BOTH models could evaluate. A pose only
// one of them can evaluate (the held-out pose solve starts from each model's
// own fitted anchors, so a start can fail under one and not the other) says
// nothing about which predicts better, and leaving it out of one side only
// would count its whole chi2 as a drop or a rise.

#include "solver/diagnosis/held_out.h"

namespace cdpr {

struct HeldOutComparison {
  int paired_poses = 0;      // poses both evaluations hold
  double drop = 0.0;         // sum of d_j: chi2 of current minus candidate
  double t_statistic = 0.0;  // mean(d) / (sd(d) / sqrt(n)); 0 below 3 paired poses or with no spread
};

HeldOutComparison compare_held_out(const HeldOutEvaluation& current, const HeldOutEvaluation& candidate);

}  // namespace cdpr
