#pragma once
// The optional model terms (effects) of docs/DESIGN.md "Model terms": their names
// in calibration.toml (`model = [...]` and [effects]), the size of their
// parameter variable (EffectKey) and how a fitted parameter becomes the
// physical value written to [effects].
//
// Parameters as the solver sees them (chosen so that 0 means "absent" and
// every term is smooth through 0):
//   elasticity     kappa = 1e6 / EA  [1/MN]   compliance; [effects] axial_stiffness = EA [N]
//   encoder_scale  s_i (4)                   reading = (1 + s_i) * payout + offset_i
//   load_cell      (b [N], g)                load cell reads (1 + g) * tension + b
//                                            ([effects] force_bias, force_gain: one term, as in
//                                            docs/DESIGN.md)
//   load_cell_bias b [N]                     the same term with g = 0 ([effects] force_bias
//                                            only). Over the tensions of a calibration b and g
//                                            are nearly collinear, so fitting both leaves b
//                                            with a sigma near its own size; a load cell whose gain is right is
//                                            named and measured far better by b alone
//   com_offset     c (3) [m, platform frame] weight acts at nominal CoM + c
//   density_error  r                         cable density = nominal * (1 + r)
//   pulley_radius  r [m]                     swivel pulley (docs/DESIGN.md)

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "solver/model/calibration.h"
#include "solver/nls/keys.h"

namespace cdpr {

enum class Effect : int {
  kElasticity,
  kEncoderScale,
  kLoadCell,
  kComOffset,
  kDensityError,
  kPulleyRadius,
  kLoadCellBias,
};
inline constexpr int kEffectCount = 7;
inline constexpr std::array<Effect, kEffectCount> kAllEffects = {
    Effect::kElasticity,   Effect::kEncoderScale,  Effect::kLoadCell,    Effect::kComOffset,
    Effect::kDensityError, Effect::kPulleyRadius, Effect::kLoadCellBias};

// Compliance unit of the elasticity parameter: kappa [1/MN] = 1e6 / EA [N].
inline constexpr double kComplianceScale = 1e-6;

inline Key EffectKey(Effect e) { return EffectKey(static_cast<int>(e)); }

// Name in `model = [...]` and on the command line: "elasticity",
// "encoder_scale", "load_cell", "com_offset",
// "density_error", "pulley_radius", "load_cell_bias".
std::string_view effect_model_name(Effect e);
std::optional<Effect> effect_from_model_name(std::string_view name);
// Size of the effect's parameter vector (1 to 4).
int effect_dimension(Effect e);
// One-line physics, for reports.
std::string_view effect_description(Effect e);

// [effects] entries of one fitted effect: its physical values under their
// truth.toml names (docs/FORMATS.md): (axial_stiffness, encoder_scale, force_bias and
// force_gain, com_offset, density_error, pulley_radius) and each 1-sigma
// under that name + "_sigma" (first order through the parameter's covariance).
void add_effect_values(Effect e, const std::vector<double>& parameter, const std::vector<double>& parameter_sigma,
                       EffectValues& out);
// Why a fitted parameter (solver units, with its 1-sigma) is physically
// impossible, or empty: a compliance or pulley radius below zero by more than
// 3 sigma, a density or load-cell gain factor (1 + r) <= 0. Such a fit means
// the term is mimicking something else.
std::string effect_domain_violation(Effect e, const std::vector<double>& value, const std::vector<double>& sigma);
// The [effects] names of the effect's physical values, in add_effect_values order.
std::vector<std::string> effect_value_names(Effect e);
// True when every parameter of `narrow` is also one of `wide`'s (load_cell
// holds load_cell_bias's bias), so that one model cannot have both: `wide`
// replaces `narrow` when added to a model that has it.
bool effect_contains(Effect wide, Effect narrow);
// Why a model's effects cannot be fitted together (an effect given twice, or
// two that share a parameter), or empty.
std::string effect_set_conflict(const std::vector<Effect>& effects);

}  // namespace cdpr
