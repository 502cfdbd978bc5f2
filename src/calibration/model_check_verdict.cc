#include "src/calibration/model_check_verdict.h"

#include <algorithm>

#include "src/calibration/message_text.h"

namespace cdpr::calibration {
namespace {

// "axial_stiffness = 1.52e+06 +- 3.1e+04" for every value of the effect.
std::string values_text(const EffectValues& values, Effect effect) {
  std::string text;
  for (const std::string& name : effect_value_names(effect)) {
    const auto value = values.find(name);
    if (value == values.end()) continue;
    const auto sigma = values.find(name + "_sigma");
    text += (text.empty() ? "" : ", ") + name + " =";
    for (std::size_t j = 0; j < value->second.size(); ++j) {
      text += (j ? ", " : " ") + significant(value->second[j], 3);
      if (sigma != values.end() && j < sigma->second.size()) text += " +- " + significant(sigma->second[j], 2);
    }
  }
  return text;
}

}  // namespace

std::string model_check_verdict(const Diagnosis& diagnosis) {
  if (!diagnosis.ok) return "model check could not run: " + diagnosis.message;
  const DiagnosisStep& last = diagnosis.steps.back();
  const std::string misfit = "held-out normalized rms " + significant(last.held_out.normalized_rms(), 3);
  std::string effects;
  for (const Effect effect : last.model) {
    effects += (effects.empty() ? "" : "; ") + std::string(effect_model_name(effect)) + ": " +
               values_text(diagnosis.final_fit.calibration.effects, effect);
  }
  if (diagnosis.structure_remains) {
    const std::string remains =
        misfit + ", p = " + significant(diagnosis.structure_p_value, 2);
    if (effects.empty()) return "structure remains that no known effect explains (" + remains + ")";
    return effects + "; structure remains (" + remains + ")";
  }
  if (effects.empty()) return "model explains the data (" + misfit + ")";
  return effects + " (explains the data: " + misfit + ")";
}

std::vector<std::string> model_check_terms(std::string_view verdict) {
  // The verdict lists each effect as "name: values", the effects separated by "; ".
  std::vector<std::string> terms;
  std::size_t begin = 0;
  while (begin < verdict.size()) {
    const std::size_t end = std::min(verdict.find("; ", begin), verdict.size());
    const std::string_view piece = verdict.substr(begin, end - begin);
    const std::size_t colon = piece.find(": ");
    if (colon != std::string_view::npos && effect_from_model_name(piece.substr(0, colon))) {
      terms.emplace_back(piece.substr(0, colon));
    }
    begin = end + 2;
  }
  return terms;
}

}  // namespace cdpr::calibration
