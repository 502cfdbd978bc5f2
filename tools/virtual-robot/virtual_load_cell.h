#pragma once
// The virtual robot's load-cell transmitter as a Modbus server application:
// a register table in one of the vendor maps (load_cell_models.h), a unit
// identifier, a reply latency and an injectable fault, answering request
// PDUs (function code + data) as the Modbus Application Protocol v1.1b3
// says a server must, independently of libmodbus and drivers/modbus:
//   0x03 (and 0x04 where the model has input registers): quantity 1..125
//   else exception 03, the whole range inside the table else exception 02;
//   0x06 and 0x10: the registers are read-only: exception 02 (0x10 with a
//   byte count that does not match its quantity: exception 03);
//   any other function: exception 01.
// The transports (modbus_tcp_server.h, modbus_rtu_server.h) frame the PDUs,
// check the unit identifier and apply the latency and the fault.
// Not thread-safe except set_fault()/fault() (atomic: tests inject faults
// from their own thread).

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "hal/clock.h"
#include "virtual-robot/load_cell_models.h"

namespace cdpr::virtual_robot {

enum class DeviceFault {
  kNone,
  kSilent,        // requests are taken and never answered
  kGarbage,       // every reply is replaced by noise of the same length
  kDisconnected,  // the transport is gone (TCP: refused; RTU: the port closes)
};

struct LoadCellServerOptions {
  LoadCellModel model = LoadCellModel::kLegacyFloat32;
  int unit_id = 1;
  hal::TimeUs reply_latency_us = 0;  // from the request's last byte to the reply
};

class VirtualLoadCell {
 public:
  explicit VirtualLoadCell(const LoadCellServerOptions& options);

  void set_reading(double tension_n, bool stable, bool error);
  std::vector<std::uint8_t> answer(std::span<const std::uint8_t> pdu);

  const LoadCellServerOptions& options() const { return options_; }
  void set_fault(DeviceFault fault) { fault_.store(fault); }
  DeviceFault fault() const { return fault_.load(); }
  // Noise for kGarbage replies (deterministic).
  std::uint8_t noise_byte();

  unsigned long long requests() const { return requests_; }
  unsigned long long exceptions() const { return exceptions_; }

 private:
  std::vector<std::uint8_t> exception(std::uint8_t function, std::uint8_t code);

  LoadCellServerOptions options_;
  RegisterTable table_{};
  std::atomic<DeviceFault> fault_{DeviceFault::kNone};
  std::uint32_t noise_state_ = 0x2545F491u;
  unsigned long long requests_ = 0;
  unsigned long long exceptions_ = 0;
};

}  // namespace cdpr::virtual_robot
