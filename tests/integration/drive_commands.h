#pragma once
// A CiA 402 master's frames for the virtual robot's drives
// (tools/virtual-robot/cia402_device.h), written here rather than taken from
// drivers/can so that a test drives them without the daemon: NMT start,
// expedited SDO downloads, controlwords and a profile-position move.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "virtual-robot/cia402_device.h"

namespace cdpr::integration {

// The daemon's default drive profile (drivers/can/device_configuration.h).
constexpr double kProfileVelocityMps = 2.0, kProfileAccelerationMps2 = 1.0;

inline void sdo_write(virtual_robot::Cia402Device& d, std::uint16_t index, std::uint32_t value, int size,
                      hal::TimeUs now_us, std::uint8_t subindex = 0) {
  virtual_robot::BusFrame f{0x600 + static_cast<std::uint32_t>(d.node_id()), 8, {}};
  f.data = {static_cast<std::uint8_t>(0x23 | (4 - size) << 2), static_cast<std::uint8_t>(index),
            static_cast<std::uint8_t>(index >> 8), subindex, static_cast<std::uint8_t>(value),
            static_cast<std::uint8_t>(value >> 8), static_cast<std::uint8_t>(value >> 16),
            static_cast<std::uint8_t>(value >> 24)};
  d.on_frame(f, now_us);
}

inline void controlword(virtual_robot::Cia402Device& d, std::uint16_t cw, hal::TimeUs now_us) {
  virtual_robot::BusFrame f{0x200 + static_cast<std::uint32_t>(d.node_id()), 2, {}};
  f.data[0] = static_cast<std::uint8_t>(cw);
  f.data[1] = static_cast<std::uint8_t>(cw >> 8);
  d.on_frame(f, now_us);
}

// NMT start, profile position mode, operation enabled.
inline void enable_profile_position(virtual_robot::Cia402Device& d, hal::TimeUs now_us) {
  d.on_frame(virtual_robot::BusFrame{0x000, 2, {0x01, static_cast<std::uint8_t>(d.node_id())}}, now_us);
  sdo_write(d, 0x6060, 1, 1, now_us);
  for (std::uint16_t cw : {0x06, 0x07, 0x0F}) controlword(d, cw, now_us);
}

// A move to `target_counts` at the profile's velocity and acceleration
// [counts/s, counts/s^2], started at once (new set-point, change immediately).
// finish_move() completes the set-point handshake.
inline void start_move(virtual_robot::Cia402Device& d, std::int32_t target_counts, double velocity, double acceleration,
                       hal::TimeUs now_us) {
  sdo_write(d, 0x6081, static_cast<std::uint32_t>(std::max(1.0, velocity)), 4, now_us);
  sdo_write(d, 0x6083, static_cast<std::uint32_t>(std::max(1.0, acceleration)), 4, now_us);
  sdo_write(d, 0x6084, static_cast<std::uint32_t>(std::max(1.0, acceleration)), 4, now_us);
  sdo_write(d, 0x607A, static_cast<std::uint32_t>(target_counts), 4, now_us);
  controlword(d, 0x3F, now_us);
}

inline void finish_move(virtual_robot::Cia402Device& d, hal::TimeUs now_us) { controlword(d, 0x2F, now_us); }

}  // namespace cdpr::integration
