#pragma once
// hal::LoadCell on Modbus RTU (serial) or TCP through libmodbus, with a
// configurable register map (drivers/modbus/load_cell_map.h).
//
// One read() = one "read holding/input registers" request covering the
// value and the status register, tried up to 1 + retries times when the
// transport failed (timeout, CRC or framing, connection lost); each try
// waits at most response_timeout_us. A Modbus exception reply is the
// device's answer and is not retried. Late replies after a timeout are
// flushed before the next try. libmodbus errno values are translated at this
// boundary (modbus_error_status): ETIMEDOUT -> kTimeout, EMBBADCRC/EMBBADDATA
// -> kCorruptData, Modbus exceptions and malformed replies -> kProtocolError,
// a dropped TCP connection -> kNotConnected (the next try reconnects once).
// The final Status names the endpoint, the number of tries and the last cause.
//
// Unit identifier: RTU 1..247 (0 is broadcast, which no device answers;
// 248..255 are reserved); TCP 0..247 or 255 (a TCP device addressed directly
// takes 0 or 255; 248..254 libmodbus 3.1 refuses).
//
// Blocks for the bus: the daemon runs it on its own thread
// (drivers/common/load_cell_reader.h). One thread at a time. Owns its
// libmodbus context (freed in close()/destructor).

#include <string>

#include "drivers/modbus/load_cell_map.h"
#include "hal/clock.h"
#include "hal/load_cell.h"

typedef struct _modbus modbus_t;  // NOLINT: libmodbus' own opaque type, no <modbus.h> here

namespace cdpr::drivers::modbus {

enum class RegisterKind { kHolding, kInput };  // function 0x03 or 0x04

struct ModbusLoadCellConfig {
  // "tcp:<host>:<port>" or "rtu:<serial device>" (e.g. rtu:/dev/ttyUSB0).
  std::string endpoint;
  int baud = 19200;        // RTU only
  char parity = 'N';       // RTU only: 'N', 'E' or 'O'
  int data_bits = 8;       // RTU only
  int stop_bits = 1;       // RTU only
  int slave_id = 1;        // unit identifier: RTU 1..247, TCP 0..247 or 255
  RegisterKind register_kind = RegisterKind::kHolding;
  LoadCellMap map;
  hal::TimeUs response_timeout_us = 200'000;
  int retries = 2;
};

// Empty when valid, else the first problem.
std::string validate(const ModbusLoadCellConfig& config);

// A libmodbus errno as hal::Status: "<device>: <operation>: <modbus_strerror>".
hal::Status modbus_error_status(int error_number, const std::string& device, const std::string& operation);

class ModbusLoadCell final : public hal::LoadCell {
 public:
  // `clock` stamps the samples and must outlive this object.
  ModbusLoadCell(ModbusLoadCellConfig config, const hal::Clock& clock);
  ~ModbusLoadCell() override;
  ModbusLoadCell(const ModbusLoadCell&) = delete;
  ModbusLoadCell& operator=(const ModbusLoadCell&) = delete;

  hal::Status open() override;
  void close() override;
  hal::Result<hal::TensionSample> read() override;

  // Counters for diagnostics.
  struct Counters {
    unsigned long long requests = 0;  // tries sent
    unsigned long long timeouts = 0;
    unsigned long long corrupt = 0;   // CRC / bad data
    unsigned long long exceptions = 0;  // Modbus exception replies (not retried)
    unsigned long long other_errors = 0;
    unsigned long long reconnects = 0;
  };
  const Counters& counters() const { return counters_; }

 private:
  hal::Status connect();
  // One request for the map's span; Ok and `registers` filled, or the translated error.
  hal::Status try_read(std::uint16_t (&registers)[kMaxSpanRegisters]);

  ModbusLoadCellConfig config_;
  const hal::Clock& clock_;
  modbus_t* context_ = nullptr;
  bool connected_ = false;
  bool tcp_ = false;  // Modbus TCP (else RTU): how a late reply is got rid of
  bool answered_ = false;  // the device replied at least once (a value or an exception)
  Counters counters_;
};

}  // namespace cdpr::drivers::modbus
