#pragma once
// Register maps of load-cell transmitters as daemon configuration values
// ([load_cell] preset = "..."; docs/fieldbus.md gives each one's manual and
// page). A preset fills the map keys; keys given next to it override them.
// Plain values: src/ does not see drivers/, main() turns them into the
// driver's LoadCellMap.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cdpr::daemon {

struct LoadCellMapConfig {
  int value_address = 0;                // protocol address (manual's 4xxxx - 40001)
  std::string value_type = "float32";   // float32, int32, uint32, int16, uint16
  std::string byte_order = "ABCD";      // ABCD, CDAB, BADC, DCBA
  int decimals = 0;                     // integer value / 10^decimals
  double scale = 1.0;                   // times the value, before the unit
  std::string unit = "N";               // N, kg (kilogram-force), lbf
  int status_address = 2;               // -1: none
  int stable_mask = 0x0001;             // 0: always stable
  bool stable_when_set = true;
  int error_mask = 0x0002;              // 0: never an error
  bool error_when_set = true;           // false: the bit means "data ok"
  int sign_mask = 0;                    // value is a magnitude, negative when set
};

// The names accepted by [load_cell] preset, in documentation order.
const std::vector<std::string_view>& load_cell_preset_names();
// The map of a preset; nullopt for an unknown name.
std::optional<LoadCellMapConfig> load_cell_preset(std::string_view name);

}  // namespace cdpr::daemon
