#pragma once
// Register map of the load cell (Modbus, 16-bit registers from a configured
// first address `base`, read in one request of 3 registers):
//
//   base + 0, base + 1   tension [N], IEEE-754 float32 in two registers.
//                        Word order configurable: kHighWordFirst ("ABCD",
//                        Modbus big-endian, the default: base+0 holds bits
//                        31-16) or kLowWordFirst ("CDAB", common on load-cell
//                        amplifiers). Bytes within a register are big-endian
//                        as Modbus transmits them (libmodbus decodes that).
//   base + 2             status bits: bit 0 = stable (reading settled),
//                        bit 1 = error (overload, broken bridge); others 0.
//
// Pure decoding, no I/O: shared by the driver and the virtual robot's server
// (encode_tension_registers) so both sides agree.

#include <cstdint>

#include "hal/status.h"

namespace cdpr::drivers::modbus {

enum class WordOrder { kHighWordFirst, kLowWordFirst };

constexpr int kTensionRegisterCount = 3;
constexpr std::uint16_t kStatusStable = 0x0001;
constexpr std::uint16_t kStatusError = 0x0002;

struct TensionRegisters {
  float tension_n = 0.0f;
  bool stable = false;
  bool error = false;
};

// Decodes the three registers. Errors: kDeviceFault when the error bit is set
// or the float is not finite (NaN/inf: a broken cell, not a tension).
hal::Result<TensionRegisters> decode_tension_registers(const std::uint16_t (&registers)[kTensionRegisterCount],
                                                       WordOrder order);

void encode_tension_registers(const TensionRegisters& value, WordOrder order,
                              std::uint16_t (&registers)[kTensionRegisterCount]);

}  // namespace cdpr::drivers::modbus
