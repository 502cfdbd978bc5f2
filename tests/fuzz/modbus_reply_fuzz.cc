// Fuzz target: Modbus replies of the load cell. libmodbus checks the frame
// (CRC, function code, byte count) and hands over the registers; what they
// mean is ours (drivers/modbus/load_cell_map.h). Any register values can
// arrive from a broken or foreign device. Input: byte 0 picks the map (value
// type, byte order, polarity of the stable and error flags, a sign bit), the
// rest are the registers (big-endian, as Modbus transmits them). Promises:
// never a crash; an accepted tension is finite; an active error flag is never
// accepted; encoding the decoded value gives registers that decode to the
// same reading.

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "drivers/modbus/load_cell_map.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::drivers::modbus;
  using cdpr::fuzz::require;
  if (size == 0) return 0;
  const std::uint8_t pick = data[0];
  LoadCellMap map;
  map.value_type = static_cast<ValueType>((pick & 7) % 5);
  map.byte_order = static_cast<ByteOrder>((pick >> 3) & 3);
  map.stable.active_when_set = (pick & 0x20) == 0;
  map.error.active_when_set = (pick & 0x40) == 0;
  if ((pick & 0x80) != 0 && map.value_type != ValueType::kFloat32) map.sign_mask = 0x0004;
  require(validate(map).empty(), "the fuzzed maps are valid");
  const RegisterSpan span = register_span(map);
  std::uint16_t registers[kMaxSpanRegisters] = {};
  for (int i = 0; i < span.count && 2 * static_cast<std::size_t>(i) + 2 < size; ++i) {
    registers[i] = static_cast<std::uint16_t>((data[2 * i + 1] << 8) | data[2 * i + 2]);
  }
  const auto decoded = decode_load_cell(map, registers);
  if (!decoded.ok()) {
    require(!decoded.status().message().empty(), "a refusal names its reason");
    return 0;
  }
  require(std::isfinite(decoded.value().tension_n), "accepted tensions are finite");
  require(!map.error.active(registers[map.status_address - span.first]), "an active error flag is never accepted");
  std::uint16_t again[kMaxSpanRegisters] = {};
  encode_load_cell(map, decoded.value().tension_n, decoded.value().stable, false, again);
  const auto redecoded = decode_load_cell(map, again);
  require(redecoded.ok() && redecoded.value().tension_n == decoded.value().tension_n &&
              redecoded.value().stable == decoded.value().stable,
          "encode(decode(registers)) decodes to the same reading");
  return 0;
}
