#include "model_option.h"

#include <sstream>

namespace cdpr::tools {

std::optional<ModelChoice> parse_model(const std::string& text, std::string* why) {
  const auto fail = [why](const std::string& reason) -> std::optional<ModelChoice> {
    if (why) *why = reason;
    return std::nullopt;
  };
  ModelChoice choice;
  std::stringstream stream(text);
  std::string name;
  bool first = true;
  while (std::getline(stream, name, ',')) {
    if (first && (name == "catenary" || name == "rigid")) {
      choice.cable_model = name == "rigid" ? CableModelKind::kRigid : CableModelKind::kCatenary;
    } else if (const std::optional<Effect> e = effect_from_model_name(name)) {
      choice.effects.push_back(*e);
      if (const std::string conflict = effect_set_conflict(choice.effects); !conflict.empty()) return fail(conflict);
    } else {
      return fail("unknown model or term '" + name + "' (models: catenary, rigid; terms: " + effect_names_text() + ")");
    }
    first = false;
  }
  if (first) return fail("empty model");
  if (choice.cable_model == CableModelKind::kRigid && !choice.effects.empty()) {
    return fail("model terms need the catenary model");
  }
  return choice;
}

std::string effect_names_text() {
  std::string text;
  for (Effect e : kAllEffects) text += (text.empty() ? "" : ", ") + std::string(effect_model_name(e));
  return text;
}

CLI::Validator model_validator() {
  return CLI::Validator(
      [](const std::string& text) {
        std::string why;
        return parse_model(text, &why) ? std::string() : why;
      },
      "MODEL[,TERM...]");
}

}  // namespace cdpr::tools
