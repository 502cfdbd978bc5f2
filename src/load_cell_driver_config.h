#pragma once
// The [load_cell] settings (plain values: src/daemon does not see drivers/)
// as the Modbus driver's configuration. For main() and the tests that run
// the daemon with its real drivers; not part of the cdpr_daemon library.

#include <cstdint>

#include "drivers/modbus/modbus_load_cell.h"
#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {

// The configuration's names (checked when it was read) as the driver's enums.
inline drivers::modbus::LoadCellMap load_cell_driver_map(const LoadCellMapConfig& c) {
  using drivers::modbus::ByteOrder;
  using drivers::modbus::ForceUnit;
  using drivers::modbus::ValueType;
  drivers::modbus::LoadCellMap m;
  m.value_address = c.value_address;
  m.value_type = c.value_type == "int32"    ? ValueType::kInt32
                 : c.value_type == "uint32" ? ValueType::kUint32
                 : c.value_type == "int16"  ? ValueType::kInt16
                 : c.value_type == "uint16" ? ValueType::kUint16
                                            : ValueType::kFloat32;
  m.byte_order = c.byte_order == "CDAB"   ? ByteOrder::kCDAB
                 : c.byte_order == "BADC" ? ByteOrder::kBADC
                 : c.byte_order == "DCBA" ? ByteOrder::kDCBA
                                          : ByteOrder::kABCD;
  m.decimals = c.decimals;
  m.scale = c.scale;
  m.unit = c.unit == "kg" ? ForceUnit::kKilogram : c.unit == "lbf" ? ForceUnit::kPoundForce : ForceUnit::kNewton;
  m.status_address = c.status_address;
  m.stable = {static_cast<std::uint16_t>(c.stable_mask), c.stable_when_set};
  m.error = {static_cast<std::uint16_t>(c.error_mask), c.error_when_set};
  m.sign_mask = static_cast<std::uint16_t>(c.sign_mask);
  return m;
}

inline drivers::modbus::ModbusLoadCellConfig load_cell_driver_config(const LoadCellConfig& c) {
  drivers::modbus::ModbusLoadCellConfig out;
  out.endpoint = c.endpoint;
  out.baud = c.baud;
  out.parity = c.parity;
  out.data_bits = c.data_bits;
  out.stop_bits = c.stop_bits;
  out.slave_id = c.slave_id;
  out.register_kind = c.input_registers ? drivers::modbus::RegisterKind::kInput : drivers::modbus::RegisterKind::kHolding;
  out.map = load_cell_driver_map(c.map);
  out.response_timeout_us = c.response_timeout_us;
  out.retries = c.retries;
  return out;
}

}  // namespace cdpr::daemon
