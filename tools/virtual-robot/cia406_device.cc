#include "virtual-robot/cia406_device.h"

namespace cdpr::virtual_robot {

Cia406Device::Cia406Device(int node_id, const EncoderDefaults& defaults)
    : CanopenDevice(node_id, defaults.identity, defaults.quirks) {
  od().add(0x6000, 0, 2, Access::kReadWrite, false, defaults.operating_parameters);  // bit 0: code sequence
  od().add(0x6001, 0, 4, Access::kReadWrite, false, defaults.counts_per_revolution);
  od().add(0x6002, 0, 4, Access::kReadWrite, false, defaults.measuring_range);
  od().add(0x6004, 0, 4, Access::kReadOnly, true, 0);
  const auto id = static_cast<std::uint32_t>(node_id);
  const std::uint32_t off = 0x80000000u;
  PdoDefault tpdo1{0x180 + id, {0x60040020}};
  add_communication_objects({PdoDefault{off | (0x200 + id), {}}, PdoDefault{off | (0x300 + id), {}},
                             PdoDefault{off | (0x400 + id), {}}, PdoDefault{off | (0x500 + id), {}}},
                            {tpdo1, PdoDefault{off | (0x280 + id), {0x60040020}}, PdoDefault{off | (0x380 + id), {}},
                             PdoDefault{off | (0x480 + id), {}}});
  od().find(0x1800, 2)->value = od().find(0x1800, 2)->default_value = 254;
}

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
