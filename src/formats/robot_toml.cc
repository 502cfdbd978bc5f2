#include "src/formats/robot_toml.h"

#include <cstdint>

#include "src/formats/text_file.h"
#include "src/formats/toml_reader.h"
#include "src/formats/toml_writer.h"

namespace cdpr::formats {
namespace {

constexpr Presence kRequired = Presence::kRequired;
constexpr Presence kOptional = Presence::kOptional;

std::vector<Winch> read_winches(TomlReader& reader, const toml::table& root) {
  std::vector<Winch> winches;
  const std::vector<const toml::table*> tables = reader.tables(root, "winch", "");
  for (std::size_t i = 0; i < tables.size(); ++i) {
    const std::string path = "winch[" + std::to_string(i) + "]";
    reader.check_keys(*tables[i], path, {{"anchor", kRequired}, {"attachment", kRequired}});
    Winch& winch = winches.emplace_back();
    winch.anchor_world = reader.vector3(*tables[i], "anchor", path);
    winch.attachment_platform = reader.vector3(*tables[i], "attachment", path);
  }
  if (reader.failed()) return winches;
  // The statics (Eq. 9-11) are square only for kCableCount cables, so any
  // other count is refused here rather than deep inside the solver.
  const int count = static_cast<int>(winches.size());
  const int line = TomlReader::line_of(*tables.front());
  if (count < 2) {
    reader.fail(line, "winch",
                "found " + std::to_string(count) + " [[winch]] table; a cable robot needs at least 2 cables");
  } else if (count != kCableCount) {
    reader.fail(line, "winch",
                "found " + std::to_string(count) + " [[winch]] tables, but the solver handles exactly " +
                    std::to_string(kCableCount) + " cables");
  }
  return winches;
}

// The index must name one of the [[winch]] tables, which are read after it.
void check_reference(TomlReader& reader, const toml::table& cable, std::int64_t reference, int cable_count) {
  if (reader.failed() || (reference >= 0 && reference < cable_count)) return;
  reader.fail(TomlReader::line_of(*cable.get("reference")), "cable.reference",
              "cable index " + std::to_string(reference) + " does not exist; cables are numbered 0.." +
                  std::to_string(cable_count - 1) + " in [[winch]] order");
}

Robot read_robot(TomlReader& reader, const toml::table& root) {
  Robot robot;

  // Later optional tables (pulley geometry, limits, waypoints) are one more
  // kOptional entry here plus their own reads.
  reader.check_keys(root, "",
                    {{"name", kRequired},
                     {"gravity", kOptional},
                     {"platform", kRequired},
                     {"cable", kRequired},
                     {"winch", kRequired},
                     {"noise", kRequired}});
  robot.name = reader.string(root, "name", "");
  robot.gravity_mps2 = reader.optional_number(root, "gravity", "", Bound::kPositive).value_or(Robot{}.gravity_mps2);

  const toml::table& platform = reader.table(root, "platform", "");
  reader.check_keys(platform, "platform", {{"mass", kRequired}, {"center_of_mass", kRequired}});
  robot.platform_mass_kg = reader.number(platform, "mass", "platform", Bound::kPositive);
  robot.center_of_mass_platform = reader.vector3(platform, "center_of_mass", "platform");

  const toml::table& cable = reader.table(root, "cable", "");
  reader.check_keys(cable, "cable",
                    {{"linear_density", kRequired}, {"reference", kRequired}, {"axial_stiffness", kOptional}});
  robot.cable_linear_density_kgpm = reader.number(cable, "linear_density", "cable", Bound::kPositive);
  const std::int64_t reference = reader.integer(cable, "reference", "cable");
  robot.axial_stiffness_n = reader.optional_number(cable, "axial_stiffness", "cable", Bound::kPositive);

  robot.winches = read_winches(reader, root);
  check_reference(reader, cable, reference, robot.cable_count());
  robot.reference_cable = static_cast<int>(reference);

  const toml::table& noise = reader.table(root, "noise", "");
  reader.check_keys(
      noise, "noise",
      {{"encoder", kRequired}, {"force", kRequired}, {"position", kRequired}, {"orientation", kRequired}});
  robot.noise.encoder_m = reader.number(noise, "encoder", "noise", Bound::kPositive);
  robot.noise.force_n = reader.number(noise, "force", "noise", Bound::kPositive);
  robot.noise.position_m = reader.number(noise, "position", "noise", Bound::kPositive);
  robot.noise.orientation_rad = reader.number(noise, "orientation", "noise", Bound::kPositive);
  return robot;
}

}  // namespace

Expected<Robot, FormatError> parse_robot_toml(std::string_view text, const std::string& source) {
  return parse_toml<Robot>(text, source, read_robot);
}

Expected<Robot, FormatError> read_robot_toml(const std::string& path) { return parse_file(path, parse_robot_toml); }

std::string format_robot_toml(const Robot& robot) {
  std::string out;
  append_line(out, "name = " + toml_string(robot.name), "free text");
  append_line(out, "gravity = " + toml_number(robot.gravity_mps2), "m/s^2");

  out += "\n[platform]\n";
  append_line(out, "mass = " + toml_number(robot.platform_mass_kg), "kg");
  append_line(out, "center_of_mass = " + toml_vector3(robot.center_of_mass_platform), "m, platform frame (nominal)");

  out += "\n[cable]\n";
  append_line(out, "linear_density = " + toml_number(robot.cable_linear_density_kgpm), "kg/m  (mass per unit length)");
  append_line(out, "reference = " + std::to_string(robot.reference_cable),
              "index of the cable whose tension the load cell measures");
  if (robot.axial_stiffness_n) {
    append_line(out, "axial_stiffness = " + toml_number(*robot.axial_stiffness_n), "EA in N");
  } else {
    append_line(out, "# axial_stiffness = 2.0e6", "EA in N; optional nominal value, absent = unknown/inextensible");
  }

  for (std::size_t i = 0; i < robot.winches.size(); ++i) {
    const Winch& winch = robot.winches[i];
    out += '\n';
    append_line(out, "[[winch]]", "cable " + std::to_string(i));
    append_line(out, "anchor = " + toml_vector3(winch.anchor_world), "m, world frame: NOMINAL pulley exit point");
    append_line(out, "attachment = " + toml_vector3(winch.attachment_platform), "m, platform frame: attachment point");
  }

  out += '\n';
  append_line(out, "[noise]", "1-sigma sensor noise, used to weight the fit");
  append_line(out, "encoder = " + toml_number(robot.noise.encoder_m), "m");
  append_line(out, "force = " + toml_number(robot.noise.force_n), "N");
  append_line(out, "position = " + toml_number(robot.noise.position_m), "m   (pose translation)");
  append_line(out, "orientation = " + toml_number(robot.noise.orientation_rad), "rad (pose rotation)");
  return out;
}

}  // namespace cdpr::formats
