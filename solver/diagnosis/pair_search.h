#pragma once
// The pair step of the model-discrepancy workflow (solver/diagnosis/diagnosis.h). Two
// effects can each be mimicked in part by a third (a cable elasticity and a
// load-cell bias together look much like a cable density error); then the
// greedy single step takes the mimic and neither true effect is significant
// on top of it. So a round with significant candidates also tries pairs of
// them.

#include <cstddef>
#include <optional>
#include <vector>

#include "solver/diagnosis/diagnosis_options.h"
#include "solver/diagnosis/held_out.h"
#include "solver/diagnosis/fit_comparison.h"
#include "solver/diagnosis/held_out_comparison.h"

namespace cdpr {

// A pair chosen over the best single candidate of a round.
struct PairChoice {
  std::size_t first = 0, second = 0;  // indices into the round's candidates, first the better ranked
  HeldOutEvaluation held_out;
  CalibrationResult fit;
  HeldOutComparison against_best;
  FitComparison over_first;  // the second term on top of the first, on all samples
  double level = 0.0;
};

// Among pairs of the round's individually significant candidates (`strong`:
// indices into `candidates`, best first, strong[0] the best single;
// `single_fits`: every candidate's fit on all samples), the one that predicts
// the held-out poses better than the best single (`best_single`, its
// cross-validation) by the largest drop, where
//   - neither term is a form of the best single: a pair with it is the
//     greedy next step, which tries every candidate, not the strong ones only;
//   - the drop is positive and the pair is the better model on all samples
//     by Akaike's criterion, penalty included (the models are not nested).
//     A positive held-out drop alone, which noise gives half the time,
//     lets a pair of mimics replace a true term; a significant paired t of
//     the held-out drops, whose noise is twice their signal, keeps a single
//     mimic in place of a true pair;
//   - each term is significant on top of the other (likelihood ratio on all
//     samples at alpha over the pairs);
//   - both fitted values are physical.
std::optional<PairChoice> best_pair(const Robot& robot, const std::vector<Sample>& samples,
                                    const DiagnosisOptions& options, const std::vector<Effect>& model,
                                    const std::vector<Effect>& candidates, const std::vector<std::size_t>& strong,
                                    const std::vector<CalibrationResult>& single_fits,
                                    const HeldOutEvaluation& best_single);

}  // namespace cdpr
