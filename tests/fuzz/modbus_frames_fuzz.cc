// Fuzz target: whole Modbus reply frames, as a broken or foreign device
// could send them, through libmodbus' own framing (TCP: MBAP header and
// transaction id; RTU: slave address, length from the function code and
// byte count, CRC) and the load-cell driver (drivers/modbus/modbus_load_cell.h)
// on a real line: a loopback TCP connection or a pseudo-terminal
// (fake_modbus_peer.h). modbus_reply covers the register decoding alone.
//
// Input: byte 0 picks the exchange (bit 0: RTU instead of TCP; bit 1: input
// registers (0x04) instead of holding (0x03); bit 2: low word first (CDAB); bit 3:
// the peer repairs the transaction id or CRC), the rest is the reply.
//
// Promises: never a crash or a hang beyond the driver's timeout; a refusal
// names the endpoint and a reason; an accepted reading comes from a reply
// that is a whole frame answering this request (its transaction id or slave
// address, its function code, three registers, a correct CRC on RTU), and is
// exactly those registers decoded.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "../fakes/manual_clock.h"
#include "../fakes/modbus_crc.h"
#include "drivers/modbus/modbus_load_cell.h"
#include "fake_modbus_peer.h"
#include "fuzz_check.h"

namespace {

using cdpr::fuzz::require;
using namespace cdpr::drivers::modbus;

// Longer than any Modbus frame (RTU 256, TCP 260 bytes): the driver must
// also cope with a device that keeps talking.
constexpr std::size_t kMaxReplyBytes = 600;
constexpr int kSlaveId = 1;

void check_accepted(const std::vector<std::uint8_t>& sent, const std::vector<std::uint8_t>& request, bool rtu,
                    bool input_registers, const LoadCellMap& map, const cdpr::hal::TensionSample& sample) {
  const std::size_t function_at = rtu ? 1 : 7;
  const int count = register_span(map).count;
  require(sent.size() >= function_at + 2 + 2 * static_cast<std::size_t>(count), "an accepted reply holds a whole frame");
  if (rtu) {
    require(sent[0] == kSlaveId, "an accepted RTU reply comes from the addressed slave");
  } else {
    require(request.size() >= 2 && sent[0] == request[0] && sent[1] == request[1],
            "an accepted TCP reply carries the request's transaction id");
  }
  require(sent[function_at] == (input_registers ? 0x04 : 0x03), "an accepted reply answers the requested function");
  const std::size_t byte_count = sent[function_at + 1];
  require(byte_count / 2 == static_cast<std::size_t>(count), "an accepted reply carries the requested registers");
  if (rtu) {
    const std::size_t end = function_at + 2 + byte_count;
    require(sent.size() >= end + 2, "an accepted RTU reply has its CRC");
    const std::uint16_t crc = cdpr::fakes::modbus_crc16(sent.data(), end);
    require(sent[end] == (crc & 0xFF) && sent[end + 1] == (crc >> 8), "an accepted RTU reply has a correct CRC");
  }
  std::uint16_t registers[kMaxSpanRegisters];
  for (int i = 0; i < count; ++i) {
    const std::size_t at = function_at + 2 + 2 * static_cast<std::size_t>(i);
    registers[i] = static_cast<std::uint16_t>((sent[at] << 8) | sent[at + 1]);
  }
  const auto decoded = decode_load_cell(map, registers);
  require(decoded.ok(), "an accepted reading decodes from the frame's registers");
  // Accepted tensions are finite, so == is exact here.
  require(decoded.value().tension_n == sample.tension_n && decoded.value().stable == sample.stable,
          "an accepted reading is the frame's registers");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool rtu = (data[0] & 1) != 0;
  const bool input_registers = (data[0] & 2) != 0;
  LoadCellMap map;  // float32 newtons at 0-1, status at 2
  map.byte_order = (data[0] & 4) != 0 ? ByteOrder::kCDAB : ByteOrder::kABCD;
  const bool repair = (data[0] & 8) != 0;
  std::vector<std::uint8_t> reply(data + 1, data + 1 + std::min(size - 1, kMaxReplyBytes));

  static cdpr::fuzz::FakeModbusPeer peer;  // keeps its TCP listener between inputs
  std::string error;
  const std::string endpoint = peer.start_exchange(rtu ? cdpr::fuzz::ModbusTransport::kRtu
                                                       : cdpr::fuzz::ModbusTransport::kTcp,
                                                   std::move(reply), repair, error);
  require(!endpoint.empty(), "the fake device's line could be set up (loopback TCP, pseudo-terminals)");

  ModbusLoadCellConfig config;
  config.endpoint = endpoint;
  config.slave_id = kSlaveId;
  config.register_kind = input_registers ? RegisterKind::kInput : RegisterKind::kHolding;
  config.map = map;
  // The peer answers at once; a frame cut short waits this long (RTU; TCP
  // sees the end of the stream).
  config.response_timeout_us = 5'000;
  config.retries = 0;
  cdpr::fakes::ManualClock clock(1'000'000);
  ModbusLoadCell cell(config, clock);
  require(cell.open().ok(), "the driver opens the fake device's line");
  const auto reading = cell.read();
  cell.close();
  peer.finish();

  if (!reading.ok()) {
    const std::string& message = reading.status().message();
    require(message.find(endpoint) != std::string::npos && message.size() > endpoint.size() + 2,
            "a refused reply names the endpoint and a reason");
    return 0;
  }
  check_accepted(peer.sent_reply(), peer.request(), rtu, input_registers, map, reading.value());
  return 0;
}
