#include "drivers/modbus/load_cell_map.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace cdpr::drivers::modbus {
namespace {

constexpr double kStandardGravity = 9.80665;    // m/s^2, kilogram-force
constexpr double kPoundKg = 0.45359237;         // international pound

std::uint16_t swap_bytes(std::uint16_t word) { return static_cast<std::uint16_t>(word << 8 | word >> 8); }
bool bytes_swapped(ByteOrder order) { return order == ByteOrder::kBADC || order == ByteOrder::kDCBA; }
bool low_word_first(ByteOrder order) { return order == ByteOrder::kCDAB || order == ByteOrder::kDCBA; }

// The value's bits as they were before the device laid them into registers.
std::uint32_t gather_bits(const LoadCellMap& map, const std::uint16_t* value_registers) {
  std::uint16_t first = value_registers[0];
  if (bytes_swapped(map.byte_order)) first = swap_bytes(first);
  if (value_register_count(map.value_type) == 1) return first;
  std::uint16_t second = value_registers[1];
  if (bytes_swapped(map.byte_order)) second = swap_bytes(second);
  const std::uint16_t high = low_word_first(map.byte_order) ? second : first;
  const std::uint16_t low = low_word_first(map.byte_order) ? first : second;
  return static_cast<std::uint32_t>(high) << 16 | low;
}

void scatter_bits(const LoadCellMap& map, std::uint32_t bits, std::uint16_t* value_registers) {
  if (value_register_count(map.value_type) == 1) {
    const auto word = static_cast<std::uint16_t>(bits);
    value_registers[0] = bytes_swapped(map.byte_order) ? swap_bytes(word) : word;
    return;
  }
  const auto high = static_cast<std::uint16_t>(bits >> 16);
  const auto low = static_cast<std::uint16_t>(bits & 0xFFFF);
  std::uint16_t first = low_word_first(map.byte_order) ? low : high;
  std::uint16_t second = low_word_first(map.byte_order) ? high : low;
  if (bytes_swapped(map.byte_order)) {
    first = swap_bytes(first);
    second = swap_bytes(second);
  }
  value_registers[0] = first;
  value_registers[1] = second;
}

double raw_value(ValueType type, std::uint32_t bits) {
  switch (type) {
    case ValueType::kFloat32: return std::bit_cast<float>(bits);
    case ValueType::kInt32: return static_cast<std::int32_t>(bits);
    case ValueType::kUint32: return bits;
    case ValueType::kInt16: return static_cast<std::int16_t>(static_cast<std::uint16_t>(bits));
    case ValueType::kUint16: return static_cast<std::uint16_t>(bits);
  }
  return 0.0;
}

std::uint32_t raw_bits(ValueType type, double value) {
  if (type == ValueType::kFloat32) return std::bit_cast<std::uint32_t>(static_cast<float>(value));
  const auto integer = static_cast<std::int64_t>(std::llround(value));
  return static_cast<std::uint32_t>(integer);  // two's complement, wraps
}

}  // namespace

double newtons_per(ForceUnit unit) {
  switch (unit) {
    case ForceUnit::kNewton: return 1.0;
    case ForceUnit::kKilogram: return kStandardGravity;
    case ForceUnit::kPoundForce: return kPoundKg * kStandardGravity;
  }
  return 1.0;
}

int value_register_count(ValueType type) {
  return type == ValueType::kInt16 || type == ValueType::kUint16 ? 1 : 2;
}

RegisterSpan register_span(const LoadCellMap& map) {
  int first = map.value_address;
  int end = map.value_address + value_register_count(map.value_type);
  if (map.status_address >= 0) {
    first = std::min(first, map.status_address);
    end = std::max(end, map.status_address + 1);
  }
  return {first, end - first};
}

std::string validate(const LoadCellMap& map) {
  if (map.value_address < 0 || map.value_address + value_register_count(map.value_type) > 0x10000) {
    return "value_address must be 0..65535 with the whole value below 65536";
  }
  if (map.status_address < -1 || map.status_address > 0xFFFF) return "status_address must be -1 (none) or 0..65535";
  if (map.status_address >= map.value_address &&
      map.status_address < map.value_address + value_register_count(map.value_type)) {
    return "status_address overlaps the value's registers";
  }
  if (register_span(map).count > kMaxSpanRegisters) {
    return "value and status registers are more than " + std::to_string(kMaxSpanRegisters) +
           " registers apart (one request reads both)";
  }
  if (map.decimals < 0 || map.decimals > 9) return "decimals must be 0..9";
  if (map.value_type == ValueType::kFloat32 && map.decimals != 0) return "decimals apply to integer values only";
  if (!std::isfinite(map.scale) || map.scale == 0.0) return "scale must be finite and not 0";
  if (map.status_address < 0 && (map.stable.mask != 0 || map.error.mask != 0 || map.sign_mask != 0)) {
    return "stable, error and sign masks need a status_address";
  }
  if (map.sign_mask != 0 && map.value_type == ValueType::kFloat32) return "sign_mask applies to integer values only";
  return {};
}

hal::Result<LoadCellReading> decode_load_cell(const LoadCellMap& map, const std::uint16_t* registers) {
  const RegisterSpan span = register_span(map);
  const std::uint16_t status = map.status_address >= 0 ? registers[map.status_address - span.first] : 0;
  if (map.error.mask != 0 && map.error.active(status)) {
    return hal::Status(hal::ErrorCode::kDeviceFault,
                       "load cell reports an error (status register " + std::to_string(status) + ")");
  }
  double value = raw_value(map.value_type, gather_bits(map, registers + (map.value_address - span.first)));
  if (!std::isfinite(value)) return hal::Status(hal::ErrorCode::kDeviceFault, "load cell reports a non-finite value");
  if (map.sign_mask != 0 && (status & map.sign_mask) != 0) value = -value;
  value /= std::pow(10.0, map.decimals);
  LoadCellReading reading;
  reading.tension_n = value * map.scale * newtons_per(map.unit);
  reading.stable = map.stable.mask == 0 || map.stable.active(status);
  return reading;
}

void encode_load_cell(const LoadCellMap& map, double shown_value, bool stable, bool error, std::uint16_t* registers) {
  const RegisterSpan span = register_span(map);
  std::uint16_t status = 0;
  const auto set_flag = [&status](const StatusFlag& flag, bool active) {
    if (active == flag.active_when_set) status |= flag.mask;
  };
  set_flag(map.stable, stable);
  set_flag(map.error, error);
  double raw = shown_value * std::pow(10.0, map.decimals);
  if (map.sign_mask != 0 && raw < 0.0) {
    status |= map.sign_mask;
    raw = -raw;
  }
  scatter_bits(map, raw_bits(map.value_type, raw), registers + (map.value_address - span.first));
  if (map.status_address >= 0) registers[map.status_address - span.first] = status;
}

}  // namespace cdpr::drivers::modbus
