#include "virtual-robot/virtual_load_cell.h"

namespace cdpr::virtual_robot {
namespace {

constexpr std::uint8_t kIllegalFunction = 0x01;
constexpr std::uint8_t kIllegalDataAddress = 0x02;
constexpr std::uint8_t kIllegalDataValue = 0x03;
constexpr int kMaxReadQuantity = 125;  // MB application protocol 6.3: 1..125 (0x7D)

int be16(std::span<const std::uint8_t> bytes, std::size_t at) { return bytes[at] << 8 | bytes[at + 1]; }

}  // namespace

VirtualLoadCell::VirtualLoadCell(const LoadCellServerOptions& options) : options_(options) {
  write_reading(options_.model, 0.0, false, false, table_);
}

void VirtualLoadCell::set_reading(double tension_n, bool stable, bool error) {
  write_reading(options_.model, tension_n, stable, error, table_);
}

std::uint8_t VirtualLoadCell::noise_byte() {
  noise_state_ ^= noise_state_ << 13;
  noise_state_ ^= noise_state_ >> 17;
  noise_state_ ^= noise_state_ << 5;
  return static_cast<std::uint8_t>(noise_state_);
}

std::vector<std::uint8_t> VirtualLoadCell::exception(std::uint8_t function, std::uint8_t code) {
  ++exceptions_;
  return {static_cast<std::uint8_t>(function | 0x80), code};
}

std::vector<std::uint8_t> VirtualLoadCell::answer(std::span<const std::uint8_t> pdu) {
  ++requests_;
  if (pdu.empty()) return exception(0, kIllegalFunction);
  const std::uint8_t function = pdu[0];
  const int count = register_count(options_.model);
  const bool read = function == 0x03 || (function == 0x04 && serves_input_registers(options_.model));
  if (read) {
    if (pdu.size() != 5) return exception(function, kIllegalDataValue);
    const int address = be16(pdu, 1);
    const int quantity = be16(pdu, 3);
    if (quantity < 1 || quantity > kMaxReadQuantity) return exception(function, kIllegalDataValue);
    if (address + quantity > count) return exception(function, kIllegalDataAddress);
    std::vector<std::uint8_t> reply = {function, static_cast<std::uint8_t>(2 * quantity)};
    for (int i = 0; i < quantity; ++i) {
      reply.push_back(static_cast<std::uint8_t>(table_[address + i] >> 8));
      reply.push_back(static_cast<std::uint8_t>(table_[address + i]));
    }
    return reply;
  }
  if (function == 0x06) {
    if (pdu.size() != 5) return exception(function, kIllegalDataValue);
    return exception(function, kIllegalDataAddress);  // no writable register
  }
  if (function == 0x10) {
    if (pdu.size() < 6) return exception(function, kIllegalDataValue);
    const int quantity = be16(pdu, 3);
    if (quantity < 1 || quantity > 123 || pdu[5] != 2 * quantity || pdu.size() != 6u + pdu[5]) {
      return exception(function, kIllegalDataValue);
    }
    return exception(function, kIllegalDataAddress);
  }
  return exception(function, kIllegalFunction);
}

}  // namespace cdpr::virtual_robot
