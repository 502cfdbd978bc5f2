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

// "; orientation noise 2.31x robot.toml; load_cell_bias or load_cell:
// indistinguishable on these poses (...)": what else the check found, for
// the end of the verdict. No piece has the "term: values" shape
// model_check_terms() reads as a term.
std::string findings_text(const Diagnosis& diagnosis) {
  std::string text;
  for (const NoiseFinding& f : diagnosis.noise) {
    text += "; " + std::string(noise_group_description(f.group)) + " " + significant(f.scale, 3) + "x robot.toml";
  }
  for (const MimicSet* set : standing_mimic_sets(diagnosis)) {
    std::string names;
    for (std::size_t j = 0; j < set->members.size(); ++j) {
      const MimicMember& m = set->members[j];
      const std::string name = m.noise ? std::string(noise_group_description(*m.noise)) + " scale"
                                       : std::string(effect_model_name(m.effect));
      names += (j == 0 ? "" : j + 1 == set->members.size() ? " or " : ", ") + name;
    }
    text += "; " + names +
            " indistinguishable on these poses (cdpr-calib diagnose proposes the waypoints that tell them apart)";
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
  const std::string findings = findings_text(diagnosis);
  if (diagnosis.structure_remains) {
    const std::string remains =
        misfit + ", p = " + significant(diagnosis.structure_p_value, 2);
    if (effects.empty()) return "structure remains that no known effect explains (" + remains + ")" + findings;
    return effects + "; structure remains (" + remains + ")" + findings;
  }
  if (effects.empty()) return "model explains the data (" + misfit + ")" + findings;
  return effects + " (explains the data: " + misfit + ")" + findings;
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
