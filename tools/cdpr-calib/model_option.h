#pragma once
// The --model option of cdpr-calib: a cable model (catenary or rigid) and
// optional model terms (solver/model/effects.h), e.g. "catenary,elasticity,load_cell_bias".

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "solver/calibration/calibrate.h"

namespace cdpr::tools {

struct ModelChoice {
  CableModelKind cable_model = CableModelKind::kCatenary;
  std::vector<Effect> effects;
};

// Empty when the text names an unknown model or term, repeats a term, or
// combines terms with the rigid model; `why` (if given) then says which.
std::optional<ModelChoice> parse_model(const std::string& text, std::string* why = nullptr);
// "elasticity, encoder_scale, ..."
std::string effect_names_text();
CLI::Validator model_validator();

}  // namespace cdpr::tools
