#include "drivers/modbus/tension_registers.h"

#include <bit>
#include <cmath>
#include <string>

namespace cdpr::drivers::modbus {

hal::Result<TensionRegisters> decode_tension_registers(const std::uint16_t (&registers)[kTensionRegisterCount],
                                                       WordOrder order) {
  const std::uint16_t high = order == WordOrder::kHighWordFirst ? registers[0] : registers[1];
  const std::uint16_t low = order == WordOrder::kHighWordFirst ? registers[1] : registers[0];
  TensionRegisters value;
  value.tension_n = std::bit_cast<float>(static_cast<std::uint32_t>(high) << 16 | low);
  value.stable = (registers[2] & kStatusStable) != 0;
  value.error = (registers[2] & kStatusError) != 0;
  if (value.error) {
    return hal::Status(hal::ErrorCode::kDeviceFault, "load cell reports an error (status register " +
                                                         std::to_string(registers[2]) + ")");
  }
  if (!std::isfinite(value.tension_n)) {
    return hal::Status(hal::ErrorCode::kDeviceFault, "load cell reports a non-finite tension");
  }
  return value;
}

void encode_tension_registers(const TensionRegisters& value, WordOrder order,
                              std::uint16_t (&registers)[kTensionRegisterCount]) {
  const auto bits = std::bit_cast<std::uint32_t>(value.tension_n);
  const auto high = static_cast<std::uint16_t>(bits >> 16);
  const auto low = static_cast<std::uint16_t>(bits & 0xFFFF);
  registers[0] = order == WordOrder::kHighWordFirst ? high : low;
  registers[1] = order == WordOrder::kHighWordFirst ? low : high;
  registers[2] = static_cast<std::uint16_t>((value.stable ? kStatusStable : 0) | (value.error ? kStatusError : 0));
}

}  // namespace cdpr::drivers::modbus
