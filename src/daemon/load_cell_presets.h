#pragma once
// Register maps of load-cell transmitters by name ([load_cell] preset = "...";
// docs/fieldbus.md gives each one's manual and page). A preset fills the map;
// the map keys given next to it override its values.

#include <optional>
#include <string_view>
#include <vector>

#include "drivers/modbus/load_cell_map.h"

namespace cdpr::daemon {

// The names accepted by [load_cell] preset, in documentation order.
const std::vector<std::string_view>& load_cell_preset_names();
// The map of a preset; nullopt for an unknown name.
std::optional<drivers::modbus::LoadCellMap> load_cell_preset(std::string_view name);

}  // namespace cdpr::daemon
