// Fuzz target: Modbus replies of the load cell. libmodbus checks the frame
// (CRC, function code, byte count) and hands over the three registers; what
// they mean is ours (drivers/modbus/tension_registers.h). Any register
// values can arrive from a broken or foreign device. Promises checked, in
// both word orders: never a crash; an accepted tension is finite and the
// error bit is never accepted; encoding the decoded value gives registers
// that decode to the same reading.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "drivers/modbus/tension_registers.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::drivers::modbus;
  using cdpr::fuzz::require;
  std::uint16_t registers[kTensionRegisterCount] = {};
  // Big-endian bytes per register, as Modbus transmits them.
  for (std::size_t i = 0; i < kTensionRegisterCount && 2 * i + 1 < size; ++i) {
    registers[i] = static_cast<std::uint16_t>((data[2 * i] << 8) | data[2 * i + 1]);
  }
  for (WordOrder order : {WordOrder::kHighWordFirst, WordOrder::kLowWordFirst}) {
    const auto decoded = decode_tension_registers(registers, order);
    if (!decoded.ok()) {
      require(!decoded.status().message().empty(), "a refusal names its reason");
      continue;
    }
    require(std::isfinite(decoded.value().tension_n), "accepted tensions are finite");
    require((registers[2] & kStatusError) == 0 && !decoded.value().error, "the error bit is never accepted");
    std::uint16_t again[kTensionRegisterCount] = {};
    encode_tension_registers(decoded.value(), order, again);
    const auto redecoded = decode_tension_registers(again, order);
    require(redecoded.ok() && std::memcmp(&redecoded.value().tension_n, &decoded.value().tension_n, sizeof(float)) == 0 &&
                redecoded.value().stable == decoded.value().stable,
            "encode(decode(registers)) decodes to the same reading");
  }
  return 0;
}
