#pragma once
// The register maps of the load-cell transmitters the virtual robot can
// pretend to be, written from the manufacturers' manuals and on purpose
// apart from drivers/modbus (a misreading shared by both sides would go
// unnoticed). docs/fieldbus.md cites the pages.
//
//   legacy-float32  float32 newtons at 0-1 (high word first), status at 2:
//                   bit 0 stable, bit 1 error; function 0x03 and 0x04.
//   flintec-ft-11   FT-11 indicator: displayed weight int32 at 40001-40002
//                   (high word first), status 40003: D1 data ok, D2 motion,
//                   D13-D15 error code; tare 40004-05, gross 40006-07.
//                   Function 0x03 only (0x10 writes the control register).
//   laumas-tlu      TLU transmitter: identification 40001-40005, command
//                   register 40006, status 40007 (bit 0 cell error, bit 1
//                   A/D malfunction, bit 7 gross negative, bit 8 net
//                   negative, bit 11 stable), gross 40008-09, net 40010-11
//                   and peak 40012-13 as magnitudes (high word first).
//                   Function 0x03 only.
// Weights of the two indicators are kilograms with kShownDecimals decimals
// (the indicators' decimal point setting), kilogram-force = 9.80665 N.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cdpr::virtual_robot {

enum class LoadCellModel { kLegacyFloat32, kFlintecFt11, kLaumasTlu };

constexpr int kLoadCellTableSize = 32;  // holding registers 0..31 exist
constexpr int kShownDecimals = 2;       // indicator resolution 0.01 kg
using RegisterTable = std::array<std::uint16_t, kLoadCellTableSize>;

// Every model, in the order of the daemon's presets (each has one of the
// same name: drivers/modbus/load_cell_presets.h).
const std::array<LoadCellModel, 3>& all_load_cell_models();
std::optional<LoadCellModel> parse_load_cell_model(std::string_view name);
std::string to_string(LoadCellModel model);

// How many registers from address 0 the model answers for (beyond: exception 02).
int register_count(LoadCellModel model);
// Whether function 0x04 (input registers) reads the same table.
bool serves_input_registers(LoadCellModel model);

// Lays a reading into the model's registers.
void write_reading(LoadCellModel model, double tension_n, bool stable, bool error, RegisterTable& table);

}  // namespace cdpr::virtual_robot
