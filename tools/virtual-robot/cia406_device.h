#pragma once
// A simulated CiA 406 linear/rotary encoder on a CanopenDevice: the
// position value 0x6004 is UNSIGNED32 and wraps at the total measuring
// range 0x6002 (a position a few counts below zero reads range - few),
// counting the other way when 0x6000 bit 0 (code sequence) is set. Its
// objects and power-on values come from its EDS (the shipped
// cdpr-virtual-encoder.eds: TPDO1 maps 0x6004, transmission type 254
// without event timer until the master sets one, then it sends
// cyclically). Written from the standard, independently of the master.
// Not thread-safe.

#include <cstdint>

#include <string>

#include "virtual-robot/canopen_device.h"
#include "virtual-robot/object_dictionary_eds.h"

namespace cdpr::virtual_robot {

struct EncoderDefaults {
  DeviceEds eds = shipped_eds("cdpr-virtual-encoder.eds");
  StoredParameters stored;  // e.g. 0x6002: another measuring range, 0x6000 = 1: counting the other way
};

class Cia406Device final : public CanopenDevice {
 public:
  // Aborts when check() refuses `defaults`: check files from outside first.
  Cia406Device(int node_id, const EncoderDefaults& defaults);
  // Empty when the encoder can play `defaults.eds`, else why not.
  static std::string check(int node_id, const EncoderDefaults& defaults);

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
