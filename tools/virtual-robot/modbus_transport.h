#pragma once
// A transport that carries a VirtualLoadCell's Modbus PDUs (TCP or RTU), run
// on the virtual robot's physics thread: nothing here waits for a client.

#include <poll.h>

#include <string>
#include <vector>

#include "hal/clock.h"

namespace cdpr::virtual_robot {

class ModbusTransport {
 public:
  virtual ~ModbusTransport() = default;
  // The daemon's [load_cell] endpoint for this transport.
  virtual std::string endpoint() const = 0;
  virtual void append_poll_fds(std::vector<pollfd>& fds) const = 0;
  // Reads what is ready in `fds`, answers whole requests and sends the
  // replies whose latency has passed at `now_us` (monotonic). Never blocks.
  virtual void service(const std::vector<pollfd>& fds, hal::TimeUs now_us) = 0;
};

}  // namespace cdpr::virtual_robot
