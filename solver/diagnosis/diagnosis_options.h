#pragma once
// What the model-discrepancy workflow (solver/diagnosis/diagnosis.h) is
// asked to do: shared by the workflow and the steps it is made of
// (model_search.h, pair_search.h).

#include <functional>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"

namespace cdpr {

struct DiagnosisOptions {
  CalibrationOptions fit;  // base options; `effects` is the starting model (usually empty)
  std::vector<Effect> candidates{kAllEffects.begin(), kAllEffects.end()};
  int folds = 3;             // cross-validation: sample k (by order) is held out in fold k % folds
  double alpha = 0.01;       // family-wise significance per round
  int max_added = 4;         // at most this many effects are added
  // When a round has a significant candidate, also try pairs of its
  // individually significant candidates and add a pair instead of the best
  // single one when it predicts the held-out poses better, is the better
  // model by Akaike's criterion on all samples and each of its terms is
  // significant on top of the other (solver/diagnosis/pair_search.h).
  bool try_pairs = true;
  std::function<void(const std::string&)> progress;  // one line per fit; may be empty
};

}  // namespace cdpr
