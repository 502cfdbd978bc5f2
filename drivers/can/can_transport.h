#pragma once
// Moves CAN frames to and from a bus. Two implementations share all protocol
// code above them (FdCanTransport): a SocketCAN raw socket on the robot, and a
// Unix stream socket to the virtual robot carrying the same frames.
//
// Thread safety: one thread at a time. Real-time safety: send() and
// receive(…, 0) never block; receive() with a timeout blocks at most that long.

#include "drivers/can/can_frame.h"
#include "hal/clock.h"
#include "hal/status.h"

namespace cdpr::drivers::can {

class CanTransport {
 public:
  virtual ~CanTransport() = default;

  // Queues one frame for transmission without blocking. Errors: kIoError
  // (transmit queue full, bus error), kNotConnected (peer gone),
  // kInvalidArgument (id > 0x7FF or len > 8).
  virtual hal::Status send(const CanFrame& frame) = 0;
  // Waits at most timeout_us for one frame. true: `frame` filled; false:
  // nothing arrived in time. Errors: kNotConnected (peer closed), kIoError,
  // kCorruptData (a malformed record, counted and skipped by the caller).
  virtual hal::Result<bool> receive(CanFrame& frame, hal::TimeUs timeout_us) = 0;
};

}  // namespace cdpr::drivers::can
