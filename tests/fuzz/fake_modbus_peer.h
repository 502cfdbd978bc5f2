#pragma once
// A scripted Modbus device for the modbus_frames fuzz target: it answers
// exactly one request of the load-cell driver with whatever bytes it is
// given, over a real Modbus TCP connection (127.0.0.1) or a real serial line
// (a pseudo-terminal, so libmodbus' RTU backend runs unchanged: open,
// termios, select, read). The reply goes out only after the request has
// arrived, as from a device. Over TCP the peer then half-closes, so a short
// reply fails at once; a serial line has no end, so there a short reply
// costs the driver's timeout.
//
// `repair_frame` lets the fuzzer past the checks it cannot guess: TCP copies
// the request's transaction id into the reply's first two bytes, RTU appends
// the reply's CRC-16.
//
// One exchange at a time: start_exchange(), run the driver, finish(). Not
// thread-safe otherwise. Setup failures (no pseudo-terminal, no loopback)
// are reported by endpoint() being empty.

#include <cstdint>
#include <string>
#include <thread>
#include <vector>

namespace cdpr::fuzz {

enum class ModbusTransport { kTcp, kRtu };

class FakeModbusPeer {
 public:
  FakeModbusPeer() = default;
  ~FakeModbusPeer();
  FakeModbusPeer(const FakeModbusPeer&) = delete;
  FakeModbusPeer& operator=(const FakeModbusPeer&) = delete;

  // Prepares the line (a listening socket, kept for later exchanges, or a
  // new pseudo-terminal) and starts answering in the background. Returns the
  // driver endpoint ("tcp:127.0.0.1:<port>" or "rtu:/dev/pts/<n>"), or ""
  // with `error` set.
  std::string start_exchange(ModbusTransport transport, std::vector<std::uint8_t> reply, bool repair_frame,
                             std::string& error);
  // Waits for the background answer to end (call after the driver closed).
  void finish();

  // The request bytes the peer received in the last exchange.
  const std::vector<std::uint8_t>& request() const { return request_; }
  // The reply as sent (after any repair).
  const std::vector<std::uint8_t>& sent_reply() const { return reply_; }

 private:
  void answer_tcp();
  void answer_rtu();

  int listen_fd_ = -1;  // TCP, kept across exchanges
  std::string tcp_endpoint_;
  int pty_master_fd_ = -1;  // RTU, one pseudo-terminal per exchange
  int pty_slave_fd_ = -1;   // held open so the line never hangs up under the driver
  bool repair_frame_ = false;
  std::vector<std::uint8_t> reply_;
  std::vector<std::uint8_t> request_;
  std::thread answering_;
};

}  // namespace cdpr::fuzz
