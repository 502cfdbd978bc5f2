#pragma once
// A committed calibration as variables of a factor graph: its anchors,
// encoder offsets and model-term parameters (solver/model/effects.h), held
// constant or free under priors of the calibration's own sigmas. What the
// operation-time problems (pose from the cables, the health test, the re-fit)
// share.

#include <optional>
#include <string>
#include <vector>

#include "solver/model/calibration.h"
#include "solver/model/effects.h"
#include "solver/nls/problem.h"

namespace cdpr {

// The model terms a calibration was fitted with (its `model` list past
// "catenary"); empty with *why set when the model cannot be used here: a
// rigid-cable calibration, an unknown term name, a count of winches other
// than kCableCount.
std::optional<std::vector<Effect>> calibration_effects(const Calibration& calibration, std::string* why);

// The solver parameter of effect `e` from its [effects] values (the inverse of
// add_effect_values), and its 1-sigma (zeros when the file has no sigma);
// empty when a value is missing or has the wrong length.
struct EffectParameter {
  std::vector<double> value;
  std::vector<double> sigma;
};
std::optional<EffectParameter> effect_parameter(Effect e, const EffectValues& values, std::string* why);

enum class CalibrationUncertainty {
  kHeldConstant,  // the calibration taken as exact
  kPriors,        // free, under priors of its sigmas (a zero sigma holds the value constant)
};

// Adds AnchorKey(i), OffsetKey(i) and EffectKey(e) for every effect of
// `effects` with the calibration's values, as `uncertainty` says. False with
// *why when an effect's values are missing.
// With kPriors and `joint` (calibration_covariance.h), the anchors and
// offsets share one prior of that covariance instead of per-axis sigmas.
bool add_calibration_variables(Problem& problem, const Calibration& calibration, const std::vector<Effect>& effects,
                               CalibrationUncertainty uncertainty, std::string* why,
                               const Eigen::Matrix<double, 4 * kCableCount, 4 * kCableCount>* joint = nullptr);

}  // namespace cdpr
