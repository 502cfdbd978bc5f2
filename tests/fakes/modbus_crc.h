#pragma once
// Modbus RTU's CRC-16 (polynomial 0xA001 reflected, initial 0xFFFF; sent low
// byte first) for fake devices that build reply frames by hand.

#include <cstddef>
#include <cstdint>

namespace cdpr::fakes {

inline std::uint16_t modbus_crc16(const std::uint8_t* data, std::size_t size) {
  std::uint16_t crc = 0xFFFF;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001) : crc >> 1;
  }
  return crc;
}

}  // namespace cdpr::fakes
