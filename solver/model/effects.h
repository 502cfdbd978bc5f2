#pragma once
// The optional model terms (effects) of docs/DESIGN.md "Model terms": one
// catalogue row per term (kEffectCatalogue below) holds every fact about it
// that is not physics: its name in calibration.toml (`model = [...]`), on the
// command line and in diagnose's candidates, the size of its parameter
// variable (EffectKey), its [effects] values with their units, how a fitted
// parameter becomes those values, its physical domain, its description for
// reports and docs. The lists that used to be written by hand (kAllEffects,
// kEffectCount, the CLI help, the docs' term tables) follow from the rows.
//
// Parameters as the solver sees them (chosen so that 0 means "absent" and
// every term is smooth through 0) are in each row's `parameters`. A note
// the rows cannot hold: load_cell_bias is load_cell with g = 0. Over the
// tensions of a calibration b and g are nearly collinear, so fitting both
// leaves b with a sigma near its own size; a load cell whose gain is right is
// named and measured far better by b alone. A model holds at most one of the two.
// A pose reference point more than 0.5 m off the platform origin along an
// axis (the large robot's platform is 1 m wide) is no marker on the
// platform: at 45 poses a 1.0-1.2 m vertical d mimics a 0.3 % scale of every
// encoder. And pose_reference_offset d: the localization reports the position of a
// point d [m, platform frame] off the platform origin, p_measured = p + R d.
// With the term the fitted pose (PoseKey) is that reference point's, so the
// pose prior is unchanged, and the platform origin the statics act on is
// p - R d (solver/calibration/effect_pose_factor.cc). Only the part of R d
// that changes with the orientation tells d from a shift of every anchor.
//
// Adding a term: an enumerator, its row (in enumerator order; a
// static_assert checks), then its physics (docs/DESIGN.md "A new model term").

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
  kPoseReferenceOffset,
};

// Compliance unit of the elasticity parameter: kappa [1/MN] = 1e6 / EA [N].
inline constexpr double kComplianceScale = 1e-6;

// One [effects] entry of a term: its truth.toml / calibration.toml name, how
// many numbers it holds, its unit ("" when dimensionless).
struct EffectValueSpec {
  std::string_view name;
  int size = 1;
  std::string_view unit;
};

// Where a fitted parameter is physically impossible (such a fit means the
// term is mimicking something else): never, below zero by more than 3 sigma,
// at a factor (1 + value) <= 0, or with a component beyond +-limit by more
// than 3 sigma.
enum class EffectDomainRule { kAny, kNotBelowZero, kPositiveFactor, kComponentsWithin };
struct EffectDomain {
  EffectDomainRule rule = EffectDomainRule::kAny;
  int parameter = 0;      // which parameter the rule reads (kComponentsWithin: every one)
  std::string_view what;  // "compliance 1/EA": the words of the violation
  double limit = 0.0;     // kComponentsWithin's bound, in the parameters' unit
};

// A fitted scalar parameter (solver units) with its 1-sigma as its physical
// value; null = the value is the parameter itself.
using EffectPhysicalValue = void (*)(double parameter, double parameter_sigma, double& value, double& value_sigma);

struct EffectDescriptor {
  Effect effect;
  std::string_view name;  // --model, `model = [...]`, --candidates
  int dimension = 1;      // parameter size (1 to 4)
  std::string_view parameters;   // what the solver fits, with its unit
  std::string_view description;  // one-line physics, for reports
  std::string_view changes;      // what it changes in the model, for docs/DESIGN.md
  std::array<EffectValueSpec, 2> values{};  // [effects] entries, the first value_count used
  int value_count = 1;
  EffectPhysicalValue physical = nullptr;
  EffectDomain domain{};
  std::string_view plausible;  // the size a real robot shows, for docs and reports
  // The narrower term whose every parameter this one also holds (load_cell
  // holds load_cell_bias's bias): one model cannot have both.
  std::optional<Effect> contains{};
};

namespace effect_rows {
void elasticity_value(double kappa, double kappa_sigma, double& ea, double& ea_sigma);
}  // namespace effect_rows

inline constexpr std::array kEffectCatalogue = {
    EffectDescriptor{Effect::kElasticity, "elasticity", 1, "compliance 1e6 / EA [1/MN] (exact elastic catenary)",
                     "cable elasticity: encoders count unstretched cable (elastic catenary, EA)",
                     "encoders count unstretched length; arc length = unstretched + stretch",
                     {EffectValueSpec{"axial_stiffness", 1, "N"}}, 1, &effect_rows::elasticity_value,
                     {EffectDomainRule::kNotBelowZero, 0, "compliance 1/EA"}, "EA 1e6-1e8 N"},
    EffectDescriptor{Effect::kEncoderScale, "encoder_scale", 4, "one scale s_i per cable",
                     "encoder scale per cable: reading = (1 + s_i) payout + offset",
                     "reading = (1 + s_i) * payout + offset", {EffectValueSpec{"encoder_scale", 4, ""}}, 1, nullptr,
                     {}, "below 1 % (drum diameter, cable layers)"},
    EffectDescriptor{Effect::kLoadCell, "load_cell", 2, "bias b [N] and gain g",
                     "load-cell bias and gain: reading = (1 + g) tension + b", "reading = (1 + g) * tension + b",
                     {EffectValueSpec{"force_bias", 1, "N"}, EffectValueSpec{"force_gain", 1, ""}}, 2, nullptr,
                     {EffectDomainRule::kPositiveFactor, 1, "load-cell gain factor"},
                     "bias within a few % of the range, gain within a few %", Effect::kLoadCellBias},
    EffectDescriptor{Effect::kComOffset, "com_offset", 3, "centre-of-mass offset c (3) [m, platform frame]",
                     "centre-of-mass offset: the weight acts at the nominal CoM + c",
                     "platform weight acts at the nominal CoM + c", {EffectValueSpec{"com_offset", 3, "m"}}, 1,
                     nullptr, {}, "within the platform's size"},
    EffectDescriptor{Effect::kDensityError, "density_error", 1, "relative cable density error r",
                     "cable density error: density = nominal (1 + r)", "true density = nominal * (1 + r)",
                     {EffectValueSpec{"density_error", 1, ""}}, 1, nullptr,
                     {EffectDomainRule::kPositiveFactor, 0, "cable density"}, "a few %"},
    EffectDescriptor{Effect::kPulleyRadius, "pulley_radius", 1, "swivel-pulley radius r [m]",
                     "swivel-pulley radius: the cable wraps a pulley of radius r at the anchor",
                     "the cable wraps a swivel pulley at the anchor (\"Swivel pulley\" below)",
                     {EffectValueSpec{"pulley_radius", 1, "m"}}, 1, nullptr,
                     {EffectDomainRule::kNotBelowZero, 0, "pulley radius"}, "0.02-0.3 m"},
    EffectDescriptor{Effect::kLoadCellBias, "load_cell_bias", 1, "bias b [N], gain taken as right",
                     "load-cell bias alone (gain right): reading = tension + b",
                     "the same with g = 0 (a model has at most one of the two)",
                     {EffectValueSpec{"force_bias", 1, "N"}}, 1, nullptr, {}, "within a few % of the range"},
    EffectDescriptor{Effect::kPoseReferenceOffset, "pose_reference_offset", 3,
                     "the localization's reference point d (3) [m, platform frame]",
                     "pose reference offset: the localization measures the point d off the platform origin",
                     "measured position = platform origin + R * d", {EffectValueSpec{"pose_reference_offset", 3, "m"}},
                     1, nullptr, {EffectDomainRule::kComponentsWithin, 0, "pose reference point", 0.5},
                     "on the platform (at most 0.5 m per axis)"},
};

inline constexpr int kEffectCount = static_cast<int>(kEffectCatalogue.size());

// The rows are in enumerator order, so an Effect indexes its row.
constexpr bool catalogue_in_enum_order() {
  for (int i = 0; i < kEffectCount; ++i) {
    if (static_cast<int>(kEffectCatalogue[i].effect) != i) return false;
  }
  return true;
}
static_assert(catalogue_in_enum_order(), "kEffectCatalogue rows must follow the Effect enumerators");

// A row's [effects] values hold its parameters, in order.
constexpr bool catalogue_values_fill_parameters() {
  for (const EffectDescriptor& d : kEffectCatalogue) {
    int size = 0;
    for (int v = 0; v < d.value_count; ++v) size += d.values[v].size;
    if (size != d.dimension || d.value_count < 1 || d.value_count > static_cast<int>(d.values.size())) return false;
  }
  return true;
}
static_assert(catalogue_values_fill_parameters(), "a kEffectCatalogue row's values must hold its parameters");

inline constexpr std::array<Effect, kEffectCount> kAllEffects = [] {
  std::array<Effect, kEffectCount> all{};
  for (int i = 0; i < kEffectCount; ++i) all[i] = kEffectCatalogue[i].effect;
  return all;
}();

inline constexpr const EffectDescriptor& effect_descriptor(Effect e) {
  return kEffectCatalogue[static_cast<int>(e)];
}

inline Key EffectKey(Effect e) { return EffectKey(static_cast<int>(e)); }

// Name in `model = [...]` and on the command line: the row's `name`.
std::string_view effect_model_name(Effect e);
std::optional<Effect> effect_from_model_name(std::string_view name);
// Size of the effect's parameter vector (1 to 4).
int effect_dimension(Effect e);
// One-line physics, for reports.
std::string_view effect_description(Effect e);

// [effects] entries of one fitted effect: its physical values under their
// truth.toml names (docs/FORMATS.md; the row's `values`) and each 1-sigma
// under that name + "_sigma" (first order through the parameter's covariance).
void add_effect_values(Effect e, const std::vector<double>& parameter, const std::vector<double>& parameter_sigma,
                       EffectValues& out);
// Why a fitted parameter (solver units, with its 1-sigma) is physically
// impossible (the row's `domain`), or empty.
std::string effect_domain_violation(Effect e, const std::vector<double>& value, const std::vector<double>& sigma);
// The [effects] names of the effect's physical values, in add_effect_values order.
std::vector<std::string> effect_value_names(Effect e);
// The unit of an [effects] value of any term ("N", "m"), "" when
// dimensionless, nullopt when no term writes that name.
std::optional<std::string_view> effect_value_unit(std::string_view value_name);
// True when every parameter of `narrow` is also one of `wide`'s (load_cell
// holds load_cell_bias's bias), so that one model cannot have both: `wide`
// replaces `narrow` when added to a model that has it.
bool effect_contains(Effect wide, Effect narrow);
// Why a model's effects cannot be fitted together (an effect given twice, or
// two that share a parameter), or empty.
std::string effect_set_conflict(const std::vector<Effect>& effects);

}  // namespace cdpr
