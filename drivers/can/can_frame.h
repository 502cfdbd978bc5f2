#pragma once
// One classic CAN frame as the protocol code sees it: 11-bit identifier,
// 0-8 data bytes. No Linux header here: the transports translate to and from
// struct can_frame (drivers/can/fd_can_transport.cc).

#include <array>
#include <cstdint>

namespace cdpr::drivers::can {

struct CanFrame {
  std::uint32_t id = 0;  // 11-bit standard identifier (CANopen COB-ID)
  std::uint8_t len = 0;  // data length 0..8
  std::array<std::uint8_t, 8> data{};
};

constexpr std::uint32_t kMaxStandardId = 0x7FF;

}  // namespace cdpr::drivers::can
