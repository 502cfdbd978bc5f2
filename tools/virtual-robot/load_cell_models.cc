#include "virtual-robot/load_cell_models.h"

#include <cmath>
#include <cstring>

namespace cdpr::virtual_robot {
namespace {

constexpr double kNewtonsPerKgf = 9.80665;

void put_u32_high_first(RegisterTable& table, int address, std::uint32_t value) {
  table[address] = static_cast<std::uint16_t>(value >> 16);
  table[address + 1] = static_cast<std::uint16_t>(value);
}

// The indicator's displayed number: kilograms with kShownDecimals decimals.
std::int64_t shown_count(double tension_n) {
  return std::llround(tension_n / kNewtonsPerKgf * std::pow(10.0, kShownDecimals));
}

void write_legacy(double tension_n, bool stable, bool error, RegisterTable& table) {
  const float value = static_cast<float>(tension_n);
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  put_u32_high_first(table, 0, bits);
  table[2] = static_cast<std::uint16_t>((stable ? 1 : 0) | (error ? 2 : 0));
}

void write_ft11(double tension_n, bool stable, bool error, RegisterTable& table) {
  const auto count = static_cast<std::int32_t>(shown_count(tension_n));
  put_u32_high_first(table, 0, static_cast<std::uint32_t>(count));  // 40001-02 display (gross)
  std::uint16_t status = 0;
  if (!error) status |= 1u << 1;       // D1 data ok
  if (!stable) status |= 1u << 2;      // D2 motion: weight not stable
  if (error) status |= 4u << 13;       // D13-D15 = 4: system fault
  table[2] = status;                   // 40003
  put_u32_high_first(table, 3, 0);     // 40004-05 tare
  put_u32_high_first(table, 5, static_cast<std::uint32_t>(count));  // 40006-07 gross
}

void write_tlu(double tension_n, bool stable, bool error, RegisterTable& table) {
  const std::int64_t count = shown_count(tension_n);
  const auto magnitude = static_cast<std::uint32_t>(count < 0 ? -count : count);
  table[0] = 0x0102;  // 40001 firmware version
  table[1] = 0x0021;  // 40002 instrument type
  table[2] = 2024;    // 40003 year of manufacture
  table[3] = 4711;    // 40004 serial number
  table[4] = 0;       // 40005 program type
  std::uint16_t status = 0;
  if (error) status |= 1u << 0;              // load cell error
  if (count < 0) status |= (1u << 7) | (1u << 8);  // gross and net negative
  if (stable) status |= 1u << 11;            // weight stability
  table[6] = status;                          // 40007
  put_u32_high_first(table, 7, magnitude);    // 40008-09 gross
  put_u32_high_first(table, 9, magnitude);    // 40010-11 net (no tare)
  put_u32_high_first(table, 11, magnitude);   // 40012-13 peak
}

}  // namespace

const std::array<LoadCellModel, 3>& all_load_cell_models() {
  static const std::array<LoadCellModel, 3> models = {LoadCellModel::kLegacyFloat32, LoadCellModel::kFlintecFt11,
                                                      LoadCellModel::kLaumasTlu};
  return models;
}

std::optional<LoadCellModel> parse_load_cell_model(std::string_view name) {
  for (const LoadCellModel model : all_load_cell_models()) {
    if (name == to_string(model)) return model;
  }
  return std::nullopt;
}

std::string to_string(LoadCellModel model) {
  switch (model) {
    case LoadCellModel::kLegacyFloat32: return "legacy-float32";
    case LoadCellModel::kFlintecFt11: return "flintec-ft-11";
    case LoadCellModel::kLaumasTlu: return "laumas-tlu";
  }
  return "?";
}

int register_count(LoadCellModel model) { return model == LoadCellModel::kLegacyFloat32 ? 3 : kLoadCellTableSize; }

bool serves_input_registers(LoadCellModel model) { return model == LoadCellModel::kLegacyFloat32; }

void write_reading(LoadCellModel model, double tension_n, bool stable, bool error, RegisterTable& table) {
  switch (model) {
    case LoadCellModel::kLegacyFloat32: write_legacy(tension_n, stable, error, table); break;
    case LoadCellModel::kFlintecFt11: write_ft11(tension_n, stable, error, table); break;
    case LoadCellModel::kLaumasTlu: write_tlu(tension_n, stable, error, table); break;
  }
}

}  // namespace cdpr::virtual_robot
