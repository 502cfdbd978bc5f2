#pragma once
// Where a load-cell transmitter keeps its reading in Modbus registers and how
// to turn those registers into a tension in newtons: the value's address,
// type and byte order, the decimal point and scale, the unit, and which bits
// of a status register say "stable" and "error" (or "data ok"), with their
// polarity. Transmitters differ in all of these (docs/fieldbus.md names the
// presets and the manual pages they come from).
//
// Addresses are protocol addresses as sent on the wire (0-based): a manual's
// holding register "40001" is address 0.
//
// Byte order of a 32-bit value with bytes A (most significant) .. D, as the
// registers carry them (each register's high byte is sent first):
//   ABCD  reg0 = A B, reg1 = C D   (Modbus big-endian, high word first)
//   CDAB  reg0 = C D, reg1 = A B   (low word first)
//   BADC  reg0 = B A, reg1 = D C   (bytes swapped in each register)
//   DCBA  reg0 = D C, reg1 = B A   (little-endian)
// A 16-bit value uses reg0 only: AB for ABCD/CDAB, BA for BADC/DCBA.
//
// Pure decoding, no I/O, no allocation on success.

#include <cstdint>
#include <string>

#include "hal/status.h"

namespace cdpr::drivers::modbus {

enum class ValueType { kFloat32, kInt32, kUint32, kInt16, kUint16 };
enum class ByteOrder { kABCD, kCDAB, kBADC, kDCBA };
enum class ForceUnit { kNewton, kKilogram, kPoundForce };

// Newtons per unit: kg as kilogram-force (standard gravity, 9.80665 m/s^2),
// lbf as the international pound-force (0.45359237 kg x 9.80665 m/s^2).
double newtons_per(ForceUnit unit);

// One flag in the status register: active when (status & mask) != 0 if
// active_when_set, when (status & mask) == 0 otherwise. mask 0: the device
// has no such flag (stable: always stable; error: never an error).
struct StatusFlag {
  std::uint16_t mask = 0;
  bool active_when_set = true;
  bool active(std::uint16_t status) const { return ((status & mask) != 0) == active_when_set; }
};

struct LoadCellMap {
  int value_address = 0;
  ValueType value_type = ValueType::kFloat32;
  ByteOrder byte_order = ByteOrder::kABCD;
  int decimals = 0;         // integer types: the value is raw / 10^decimals (0..9)
  double scale = 1.0;       // multiplies the value, before the unit (calibration factor, sign)
  ForceUnit unit = ForceUnit::kNewton;
  int status_address = 2;   // -1: no status register
  StatusFlag stable{0x0001, true};
  StatusFlag error{0x0002, true};
  // Sign-and-magnitude transmitters report |value| and a "negative" status
  // bit: the value is negated when (status & sign_mask) != 0. 0: no such bit.
  std::uint16_t sign_mask = 0;
};

// Registers one request must read to cover the value and the status.
struct RegisterSpan {
  int first = 0;
  int count = 0;
};
constexpr int kMaxSpanRegisters = 16;  // value and status this close together

int value_register_count(ValueType type);
RegisterSpan register_span(const LoadCellMap& map);

// Empty when usable, else the first problem ("decimals must be 0..9").
std::string validate(const LoadCellMap& map);

struct LoadCellReading {
  double tension_n = 0.0;
  bool stable = false;
};

// `registers` holds span.count registers from span.first (register_span).
// Errors: kDeviceFault when the error flag is active (naming the status
// word) or the value is not finite (a float32 NaN/inf: a broken cell).
hal::Result<LoadCellReading> decode_load_cell(const LoadCellMap& map, const std::uint16_t* registers);

// The inverse, for fakes and round-trip tests: writes value and status into
// `registers` (span.count of them from span.first, others left alone);
// `shown_value` is what the transmitter shows, in its unit, before `scale`.
// Integers are rounded; out-of-range ones wrap.
void encode_load_cell(const LoadCellMap& map, double shown_value, bool stable, bool error, std::uint16_t* registers);

}  // namespace cdpr::drivers::modbus
