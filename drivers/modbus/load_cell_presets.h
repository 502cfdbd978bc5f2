#pragma once
// The load-cell transmitters the daemon knows by name ([load_cell] preset =
// "..."): one row each, its register map and the manual page it follows
// (docs/fieldbus.md quotes them). A preset fills the map; the map keys
// given next to it override its values. The configuration's choice list,
// its docs and the tests that go through every transmitter all read this
// table: a new transmitter is a row here, its virtual counterpart in
// tools/virtual-robot/load_cell_models.cc (written apart from this on
// purpose, so that a misreading is not shared) and its line in
// docs/fieldbus.md.

#include <optional>
#include <string_view>
#include <vector>

#include "drivers/modbus/load_cell_map.h"

namespace cdpr::drivers::modbus {

struct LoadCellPreset {
  std::string_view name;    // the [load_cell] preset value
  std::string_view manual;  // the manual and page of its register map
  LoadCellMap map;
};

// Every preset, in documentation order; the first is the default.
const std::vector<LoadCellPreset>& load_cell_presets();
// The names of load_cell_presets(), in the same order.
std::vector<std::string_view> load_cell_preset_names();
// The map of a preset; nullopt for an unknown name.
std::optional<LoadCellMap> load_cell_preset(std::string_view name);

}  // namespace cdpr::drivers::modbus
