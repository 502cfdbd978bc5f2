#include "virtual-robot/cia406_device.h"

#include <cstdio>
#include <utility>

namespace cdpr::virtual_robot {

namespace {

std::string missing_encoder_object(const ObjectDictionary& od) {
  for (const std::uint16_t index : {0x6000, 0x6001, 0x6002, 0x6004}) {
    if (od.find(index, 0) == nullptr) {
      char text[64];
      std::snprintf(text, sizeof(text), "no object 0x%04X:00, which the encoder plays", index);
      return text;
    }
  }
  return CanopenDevice::check_communication_objects(od);
}

}  // namespace

std::string Cia406Device::check(int node_id, const EncoderDefaults& defaults) {
  std::string error;
  (void)dictionary_from_eds(defaults.eds, node_id, defaults.stored, missing_encoder_object, error);
  return error;
}

Cia406Device::Cia406Device(int node_id, const EncoderDefaults& defaults)
    : CanopenDevice(node_id, [&] {
        std::string error;
        ObjectDictionary od = dictionary_from_eds(defaults.eds, node_id, defaults.stored, missing_encoder_object, error);
        return dictionary_or_abort("Cia406Device", std::move(od), error);
      }()) {}

std::uint32_t Cia406Device::position_value() const {
  const auto range = static_cast<std::int64_t>(od().get(0x6002, 0));
  const std::int64_t counts = (od().get(0x6000, 0) & 0x0001) != 0 ? -position_counts_ : position_counts_;
  return static_cast<std::uint32_t>(((counts % range) + range) % range);
}

std::uint32_t Cia406Device::check_write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) {
  (void)subindex;
  return (index == 0x6002 || index == 0x6001) && value == 0 ? abort_code::kInvalidValue : 0;
}

void Cia406Device::before_tpdo(hal::TimeUs now_us) {
  (void)now_us;
  od().set(0x6004, 0, position_value());
}

}  // namespace cdpr::virtual_robot
