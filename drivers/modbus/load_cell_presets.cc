#include "drivers/modbus/load_cell_presets.h"

namespace cdpr::drivers::modbus {
namespace {

// The map this daemon always read (and the virtual robot's default):
// float32 newtons at 0-1, status at 2 with bit 0 stable and bit 1 error.
LoadCellMap legacy_float32() {
  LoadCellMap m;
  m.value_address = 0;
  m.value_type = ValueType::kFloat32;
  m.byte_order = ByteOrder::kABCD;
  m.unit = ForceUnit::kNewton;
  m.status_address = 2;
  m.stable = {0x0001, true};
  m.error = {0x0002, true};
  return m;
}

// Flintec FT-11 indicator, Modbus RTU appendix: the displayed weight as a
// 32-bit integer at 40001-40002 (high word first), status at 40003 with
// D1 "data ok" (0: error, code in D13-D15) and D2 "motion" (1: not stable).
// The decimal point and unit are the indicator's settings (kg by default).
LoadCellMap flintec_ft11() {
  LoadCellMap m;
  m.value_address = 0;
  m.value_type = ValueType::kInt32;
  m.unit = ForceUnit::kKilogram;
  m.status_address = 2;
  m.stable = {0x0004, false};
  m.error = {0x0002, false};
  return m;
}

// Laumas TLU transmitter: status register 40007, gross weight 40008 (high)
// and 40009 (low) as a positive integer without decimal point, its sign in
// status bit 7. Status bits 0-4 (load cell error, A/D converter
// malfunction, maximum weight exceeded by 9 divisions, gross above 110 % of
// full scale, gross beyond +-999999) make the reading unusable; bit 11 is
// "weight stability".
LoadCellMap laumas_tlu() {
  LoadCellMap m;
  m.value_address = 7;
  m.value_type = ValueType::kUint32;
  m.unit = ForceUnit::kKilogram;
  m.status_address = 6;
  m.stable = {0x0800, true};
  m.error = {0x001F, true};
  m.sign_mask = 0x0080;
  return m;
}

}  // namespace

const std::vector<LoadCellPreset>& load_cell_presets() {
  static const std::vector<LoadCellPreset> presets = {
      {"legacy-float32", "the map this daemon always read", legacy_float32()},
      {"flintec-ft-11", "Flintec FT-11 manual p. 42 (Modbus RTU appendix)", flintec_ft11()},
      {"laumas-tlu", "Laumas TLU manual p. 30; LCB p. 3; WTS p. 46", laumas_tlu()},
  };
  return presets;
}

std::vector<std::string_view> load_cell_preset_names() {
  std::vector<std::string_view> names;
  for (const LoadCellPreset& preset : load_cell_presets()) names.push_back(preset.name);
  return names;
}

std::optional<LoadCellMap> load_cell_preset(std::string_view name) {
  for (const LoadCellPreset& preset : load_cell_presets()) {
    if (preset.name == name) return preset.map;
  }
  return std::nullopt;
}

}  // namespace cdpr::drivers::modbus
