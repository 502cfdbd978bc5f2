#pragma once
// The load cell on the reference cable (docs/DESIGN.md: one, on Modbus RTU or TCP).
//
// Lifecycle: construct (configuration only, no I/O) -> open() -> read()* ->
// close(). open() may be called again after close() or after a read() that
// returned kNotConnected, to reconnect.
//
// Units: tension [N] along the cable at the winch, as the cell reports it (no
// bias/gain correction here: those are calibration effects, docs/DESIGN.md).
// Time: time_us is the local monotonic time (hal::Clock of the driver) when the
// reply arrived.
// Thread safety: one thread at a time per instance. Real-time safety: a bus
// driver's read() blocks for a transaction, at most response_timeout x
// (1 + retries) of its configuration, and open() may block longer; the daemon
// therefore runs the bus driver behind drivers/common/load_cell_reader.h,
// whose read() never blocks and returns the latest reading, possibly the same
// one again (compare time_us).

#include "hal/clock.h"
#include "hal/status.h"

namespace cdpr::hal {

struct TensionSample {
  double tension_n = 0.0;  // [N]
  bool stable = false;     // the cell's own "reading settled" flag
  TimeUs time_us = 0;      // local monotonic time of the reply [us]
};

class LoadCell {
 public:
  virtual ~LoadCell() = default;

  // Connects to the device (TCP connect or serial port setup). Errors:
  // kNotConnected (refused, no such port), kInvalidArgument (bad config).
  virtual Status open() = 0;
  // Releases the connection; safe to call twice or without open().
  virtual void close() = 0;
  // One fresh measurement. Errors: kTimeout (no reply after all retries),
  // kCorruptData (CRC/framing), kProtocolError (Modbus exception, bad reply),
  // kDeviceFault (cell reports an error or a non-finite value),
  // kNotConnected (connection lost: call open() again), kInvalidState (not open).
  virtual Result<TensionSample> read() = 0;
};

}  // namespace cdpr::hal
