#pragma once
// Lists of single sensor readings as arrays of tables: calibration.toml's
// [[rejected]] (readings a calibration refused as gross errors, `residual`
// in sigmas) and truth.toml's [[outlier]] (readings a simulator made wrong
// on purpose, `error` in m or N). Each table: row (sample id), sensor
// ("encoder" or "force"), cable, the value key, and an optional `group`
// (SensorReading::group; absent when 0, so files without it still read).

#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "solver/model/calibration.h"
#include "src/formats/toml_reader.h"

namespace cdpr::formats {

// Reads the optional [[table_key]] array of `root`; empty when absent.
std::vector<SensorReading> read_sensor_readings(TomlReader& reader, const toml::table& root, std::string_view table_key,
                                                std::string_view value_key);

// Appends one [[table_key]] table per reading (nothing when empty).
void append_sensor_readings(std::string& out, const std::vector<SensorReading>& readings, std::string_view table_key,
                            std::string_view value_key, std::string_view value_comment);

}  // namespace cdpr::formats
