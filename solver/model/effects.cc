#include "solver/model/effects.h"

#include <cmath>
#include <cstdio>

namespace cdpr {

namespace effect_rows {

// EA = 1 / (kappa * 1e-6); sigma by first order: sigma_EA = sigma_kappa * EA / kappa.
void elasticity_value(double kappa, double kappa_sigma, double& ea, double& ea_sigma) {
  ea = 1.0 / (kappa * kComplianceScale);
  ea_sigma = std::abs(ea / kappa) * kappa_sigma;
}

}  // namespace effect_rows

std::string_view effect_model_name(Effect e) { return effect_descriptor(e).name; }

std::vector<std::string> effect_value_names(Effect e) {
  const EffectDescriptor& d = effect_descriptor(e);
  std::vector<std::string> names;
  for (int v = 0; v < d.value_count; ++v) names.emplace_back(d.values[v].name);
  return names;
}

std::optional<std::string_view> effect_value_unit(std::string_view value_name) {
  for (const EffectDescriptor& d : kEffectCatalogue) {
    for (int v = 0; v < d.value_count; ++v) {
      if (d.values[v].name == value_name) return d.values[v].unit;
    }
  }
  return std::nullopt;
}

std::optional<Effect> effect_from_model_name(std::string_view name) {
  for (const EffectDescriptor& d : kEffectCatalogue) {
    if (d.name == name) return d.effect;
  }
  return std::nullopt;
}

int effect_dimension(Effect e) { return effect_descriptor(e).dimension; }

std::string_view effect_description(Effect e) { return effect_descriptor(e).description; }

bool effect_contains(Effect wide, Effect narrow) { return effect_descriptor(wide).contains == narrow; }

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
  const EffectDomain& domain = effect_descriptor(e).domain;
  const std::size_t j = static_cast<std::size_t>(domain.parameter);
  switch (domain.rule) {
    case EffectDomainRule::kAny: return {};
    case EffectDomainRule::kNotBelowZero:
      return value.at(j) < -3.0 * sigma.at(j) ? std::string(domain.what) + " below zero by more than 3 sigma" : "";
    case EffectDomainRule::kPositiveFactor:
      return value.at(j) <= -1.0 ? std::string(domain.what) + " not positive" : "";
    case EffectDomainRule::kComponentsWithin:
      for (std::size_t k = 0; k < value.size(); ++k) {
        if (std::abs(value[k]) - 3.0 * sigma.at(k) > domain.limit) {
          char limit[32];
          std::snprintf(limit, sizeof limit, "%g", domain.limit);
          const std::string_view unit = effect_descriptor(e).values[0].unit;
          return std::string(domain.what) + " beyond " + limit + " " + std::string(unit) + " by more than 3 sigma";
        }
      }
      return {};
  }
  return {};
}

void add_effect_values(Effect e, const std::vector<double>& parameter, const std::vector<double>& parameter_sigma,
                       EffectValues& out) {
  const EffectDescriptor& d = effect_descriptor(e);
  std::size_t first = 0;
  for (int v = 0; v < d.value_count; ++v) {
    const EffectValueSpec& spec = d.values[v];
    const std::string name(spec.name);
    const auto begin = static_cast<std::ptrdiff_t>(first), end = begin + spec.size;
    std::vector<double> value(parameter.begin() + begin, parameter.begin() + end);
    std::vector<double> sigma(parameter_sigma.begin() + begin, parameter_sigma.begin() + end);
    if (d.physical) {
      for (std::size_t j = 0; j < value.size(); ++j) d.physical(value[j], sigma[j], value[j], sigma[j]);
    }
    out[name] = std::move(value);
    out[name + "_sigma"] = std::move(sigma);
    first += static_cast<std::size_t>(spec.size);
  }
}

}  // namespace cdpr
