#include "solver/model/effects.h"

#include <cmath>

namespace cdpr {

std::string_view effect_model_name(Effect e) {
  switch (e) {
    case Effect::kElasticity: return "elasticity";
    case Effect::kEncoderScale: return "encoder_scale";
    case Effect::kLoadCell: return "load_cell";
    case Effect::kComOffset: return "com_offset";
    case Effect::kDensityError: return "density_error";
    case Effect::kPulleyRadius: return "pulley_radius";
    case Effect::kLoadCellBias: return "load_cell_bias";
  }
  return "?";
}

std::vector<std::string> effect_value_names(Effect e) {
  if (e == Effect::kElasticity) return {"axial_stiffness"};
  if (e == Effect::kLoadCell) return {"force_bias", "force_gain"};
  if (e == Effect::kLoadCellBias) return {"force_bias"};
  return {std::string(effect_model_name(e))};
}

std::optional<Effect> effect_from_model_name(std::string_view name) {
  for (Effect e : kAllEffects) {
    if (effect_model_name(e) == name) return e;
  }
  return std::nullopt;
}

int effect_dimension(Effect e) {
  switch (e) {
    case Effect::kEncoderScale: return 4;
    case Effect::kComOffset: return 3;
    case Effect::kLoadCell: return 2;
    default: return 1;
  }
}

std::string_view effect_description(Effect e) {
  switch (e) {
    case Effect::kElasticity: return "cable elasticity: encoders count unstretched cable (elastic catenary, EA)";
    case Effect::kEncoderScale: return "encoder scale per cable: reading = (1 + s_i) payout + offset";
    case Effect::kLoadCell: return "load-cell bias and gain: reading = (1 + g) tension + b";
    case Effect::kComOffset: return "centre-of-mass offset: the weight acts at the nominal CoM + c";
    case Effect::kDensityError: return "cable density error: density = nominal (1 + r)";
    case Effect::kPulleyRadius: return "swivel-pulley radius: the cable wraps a pulley of radius r at the anchor";
    case Effect::kLoadCellBias: return "load-cell bias alone (gain right): reading = tension + b";
  }
  return "?";
}

bool effect_contains(Effect wide, Effect narrow) {
  return wide == Effect::kLoadCell && narrow == Effect::kLoadCellBias;
}

std::string effect_set_conflict(const std::vector<Effect>& effects) {
  for (std::size_t a = 0; a < effects.size(); ++a) {
    for (std::size_t b = a + 1; b < effects.size(); ++b) {
      const std::string first(effect_model_name(effects[a])), second(effect_model_name(effects[b]));
      if (effects[a] == effects[b]) return "model term " + first + " given twice";
      if (effect_contains(effects[a], effects[b]) || effect_contains(effects[b], effects[a])) {
        return "model terms " + first + " and " + second + " share a parameter: give one of them";
      }
    }
  }
  return {};
}

std::string effect_domain_violation(Effect e, const std::vector<double>& value, const std::vector<double>& sigma) {
  const auto below_zero = [&](const char* what) -> std::string {
    if (value.at(0) < -3.0 * sigma.at(0)) return std::string(what) + " below zero by more than 3 sigma";
    return {};
  };
  switch (e) {
    case Effect::kElasticity: return below_zero("compliance 1/EA");
    case Effect::kPulleyRadius: return below_zero("pulley radius");
    case Effect::kDensityError: return value.at(0) <= -1.0 ? "cable density not positive" : "";
    case Effect::kLoadCell: return value.at(1) <= -1.0 ? "load-cell gain factor not positive" : "";
    default: return {};
  }
}

void add_effect_values(Effect e, const std::vector<double>& parameter, const std::vector<double>& parameter_sigma,
                       EffectValues& out) {
  const std::string name = effect_value_names(e).front();
  if (e == Effect::kLoadCell) {
    out["force_bias"] = {parameter.at(0)};
    out["force_bias_sigma"] = {parameter_sigma.at(0)};
    out["force_gain"] = {parameter.at(1)};
    out["force_gain_sigma"] = {parameter_sigma.at(1)};
    return;
  }
  if (e == Effect::kElasticity) {
    // EA = 1 / (kappa * 1e-6); sigma by first order: sigma_EA = sigma_kappa * EA / kappa.
    const double kappa = parameter.at(0);
    const double ea = 1.0 / (kappa * kComplianceScale);
    out[name] = {ea};
    out[name + "_sigma"] = {std::abs(ea / kappa) * parameter_sigma.at(0)};
    return;
  }
  out[name] = parameter;
  out[name + "_sigma"] = parameter_sigma;
}

}  // namespace cdpr
