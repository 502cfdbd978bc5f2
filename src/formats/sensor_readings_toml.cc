#include "src/formats/sensor_readings_toml.h"

#include "src/formats/toml_writer.h"

namespace cdpr::formats {

std::vector<SensorReading> read_sensor_readings(TomlReader& reader, const toml::table& root, std::string_view table_key,
                                                std::string_view value_key) {
  std::vector<SensorReading> readings;
  if (!root.contains(table_key)) return readings;
  for (const toml::table* table : reader.tables(root, table_key, "")) {
    const std::string path = std::string(table_key) + "[" + std::to_string(readings.size()) + "]";
    reader.check_keys(*table, path,
                      {{"row", Presence::kRequired},
                       {"sensor", Presence::kRequired},
                       {"cable", Presence::kRequired},
                       {value_key, Presence::kRequired},
                       {"group", Presence::kOptional}});
    SensorReading& reading = readings.emplace_back();
    reading.row = reader.count(*table, "row", path);
    const std::string sensor = reader.string(*table, "sensor", path);
    if (!reader.failed() && sensor != "encoder" && sensor != "force") {
      reader.fail(TomlReader::line_of(*table->get("sensor")), join_key(path, "sensor"),
                  "expected \"encoder\" or \"force\", got \"" + sensor + "\"");
    }
    reading.sensor = sensor == "force" ? SensorKind::kForce : SensorKind::kEncoder;
    reading.cable = reader.count(*table, "cable", path);
    reading.value = reader.number(*table, value_key, path);
    if (table->contains("group")) reading.group = reader.count(*table, "group", path);
  }
  return readings;
}

void append_sensor_readings(std::string& out, const std::vector<SensorReading>& readings, std::string_view table_key,
                            std::string_view value_key, std::string_view value_comment) {
  for (const SensorReading& reading : readings) {
    out += "\n[[" + std::string(table_key) + "]]\n";
    append_line(out, "row = " + std::to_string(reading.row), "sample id");
    append_line(out, "sensor = " + toml_string(sensor_name(reading.sensor)));
    append_line(out, "cable = " + std::to_string(reading.cable));
    append_line(out, std::string(value_key) + " = " + toml_number(reading.value), std::string(value_comment));
    if (reading.group != 0) {
      append_line(out, "group = " + std::to_string(reading.group), "suspect group within its row: one of them is wrong");
    }
  }
}

}  // namespace cdpr::formats
