#pragma once
// A simulated CiA 406 linear/rotary encoder on a CanopenDevice: the
// position value 0x6004 is UNSIGNED32 and wraps at the total measuring
// range 0x6002 (a position a few counts below zero reads range - few),
// counting the other way when 0x6000 bit 0 (code sequence) is set;
// predefined TPDO1 maps 0x6004, transmission type 254 without event timer
// until the master sets one (then it sends cyclically). Written from the
// standard, independently of the master. Not thread-safe.

#include <cstdint>

#include "virtual-robot/canopen_device.h"

namespace cdpr::virtual_robot {

struct EncoderDefaults {
  DeviceIdentity identity{0x00020196, 0x0000CD42, 0x00000406, 1, 0};
  std::uint32_t measuring_range = 1u << 25;  // 0x6002 [counts]
  std::uint16_t operating_parameters = 0;     // 0x6000: bit 0 code sequence (1: counts down where 0 counts up)
  std::uint32_t counts_per_revolution = 4096; // 0x6001
  CommunicationQuirks quirks;
};

class Cia406Device final : public CanopenDevice {
 public:
  Cia406Device(int node_id, const EncoderDefaults& defaults);

  // The encoder's position from the mechanics [counts, unbounded]; it
  // reports it modulo the measuring range.
  void set_position_counts(std::int64_t counts) { position_counts_ = counts; }
  std::uint32_t position_value() const;

 private:
  void before_tpdo(hal::TimeUs now_us) override;
  std::uint32_t check_write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) override;

  std::int64_t position_counts_ = 0;
};

}  // namespace cdpr::virtual_robot
