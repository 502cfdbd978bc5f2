// truth.toml (docs/FORMATS.md): the ground truth a simulator wrote next to its
// data set; read only by evaluation, never by calibration.
#include "src/formats/calibration_toml.h"

#include <algorithm>

#include "src/formats/effects_toml.h"
#include "src/formats/sensor_readings_toml.h"
#include "src/formats/toml_reader.h"
#include "src/formats/toml_writer.h"

namespace cdpr::formats {
namespace {

// Evaluation input must never stop a calibration: an [effects] value that is
// not a number or a list of numbers is kept by name as not compared.
void read_truth_effects(TomlReader& reader, const toml::table& root, Truth& truth) {
  const toml::table& table = reader.table(root, "effects", "", Presence::kOptional);
  for (auto&& [name, node] : table) {
    bool numbers = node.is_number();
    if (const toml::array* array = node.as_array()) {
      numbers = !array->empty() && std::all_of(array->begin(), array->end(), [](const toml::node& v) { return v.is_number(); });
    }
    if (numbers) {
      truth.effects[std::string(name.str())] = reader.number_or_numbers(node, join_key("effects", name.str()));
    } else {
      truth.uncompared_effects.emplace_back(name.str());
    }
  }
}

Truth read_truth(TomlReader& reader, const toml::table& root) {
  Truth truth;
  reader.check_keys(root, "",
                    {{"winch", Presence::kRequired}, {"effects", Presence::kOptional}, {"outlier", Presence::kOptional}});
  for (const toml::table* table : reader.tables(root, "winch", "")) {
    const std::string path = "winch[" + std::to_string(truth.winches.size()) + "]";
    reader.check_keys(*table, path, {{"anchor", Presence::kRequired}, {"offset", Presence::kRequired}});
    WinchTruth& winch = truth.winches.emplace_back();
    winch.anchor_world = reader.vector3(*table, "anchor", path);
    winch.offset_m = reader.number(*table, "offset", path);
  }
  read_truth_effects(reader, root, truth);
  truth.outliers = read_sensor_readings(reader, root, "outlier", "error");
  return truth;
}

}  // namespace

Expected<Truth, FormatError> parse_truth_toml(std::string_view text, const std::string& source) {
  return parse_toml<Truth>(text, source, read_truth);
}

Expected<Truth, FormatError> read_truth_toml(const std::string& path) { return parse_file(path, parse_truth_toml); }

std::string format_truth_toml(const Truth& truth) {
  std::string out;
  for (std::size_t i = 0; i < truth.winches.size(); ++i) {
    if (i > 0) out += '\n';
    append_line(out, "[[winch]]", "cable " + std::to_string(i));
    append_line(out, "anchor = " + toml_vector3(truth.winches[i].anchor_world), "m, true pulley exit point");
    append_line(out, "offset = " + toml_number(truth.winches[i].offset_m), "m, true encoder offset");
  }
  append_effects(out, truth.effects);
  append_sensor_readings(out, truth.outliers, "outlier", "error", "m (encoder) or N (force), reading - true");
  return out;
}

}  // namespace cdpr::formats
