#include "src/formats/effects_toml.h"

#include "src/formats/toml_writer.h"

namespace cdpr::formats {

EffectValues read_effects(TomlReader& reader, const toml::table& root) {
  EffectValues effects;
  const toml::table& table = reader.table(root, "effects", "", Presence::kOptional);
  for (auto&& [name, node] : table) {
    effects[std::string(name.str())] = reader.number_or_numbers(node, join_key("effects", name.str()));
  }
  return effects;
}

void append_effects(std::string& out, const EffectValues& effects) {
  if (effects.empty()) return;
  out += "\n[effects]\n";
  for (const auto& [name, values] : effects) {
    append_line(out, toml_key(name) + " = " + (values.size() == 1 ? toml_number(values[0]) : toml_numbers(values)));
  }
}

}  // namespace cdpr::formats
