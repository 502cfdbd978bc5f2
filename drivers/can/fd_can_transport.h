#pragma once
// CanTransport over a file descriptor carrying Linux `struct can_frame`
// records, for both transports the daemon uses:
//   * SocketCAN: a PF_CAN/SOCK_RAW/CAN_RAW socket bound to an interface
//     (open_socketcan). Each read/write is one record.
//   * Unix stream socket to the virtual robot (connect_unix, or adopt an fd
//     from socketpair()/accept()). The byte stream is a plain sequence of the
//     same 16-byte records, verbatim as in <linux/can.h>, with no other
//     framing:
//        bytes 0-3   can_id   uint32, host byte order; bits 0-10 the 11-bit
//                             identifier; flag bits 29-31 (ERR, RTR, EFF)
//                             must be 0 (only classic data frames are used)
//        byte  4     len      data length 0..8 (can_dlc)
//        bytes 5-7   pad, res0, len8_dlc: 0 when sent, ignored when read
//        bytes 8-15  data     len bytes used, the rest 0 when sent
//     Both ends run on the same machine, so host byte order is shared.
// The protocol code above (CANopen) cannot tell the two apart.
//
// Ownership: the transport owns its fd and closes it. Buffers are fixed-size
// (no allocation after construction). Thread safety: one thread at a time.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/can/can_transport.h"

namespace cdpr::drivers::can {

inline constexpr std::size_t kWireFrameBytes = 16;

// The wire record of `frame` (layout above). Precondition: id <= 0x7FF, len <= 8.
void encode_wire_frame(const CanFrame& frame, std::uint8_t (&out)[kWireFrameBytes]);
// Decodes one record; false when a flag bit is set or len > 8.
bool decode_wire_frame(const std::uint8_t* in, CanFrame& frame);

class FdCanTransport final : public CanTransport {
 public:
  // Adopts `fd` (made non-blocking); `name` appears in error messages.
  FdCanTransport(int fd, std::string name);
  ~FdCanTransport() override;
  FdCanTransport(const FdCanTransport&) = delete;
  FdCanTransport& operator=(const FdCanTransport&) = delete;

  // A raw CAN socket on `interface` ("can0"). Fails with kUnsupported and a
  // clear message when the kernel has no AF_CAN (as on this build machine),
  // kNotConnected when the interface does not exist.
  static hal::Result<std::unique_ptr<FdCanTransport>> open_socketcan(const std::string& interface);
  // A Unix stream connection to the virtual robot's CAN socket at `path`.
  static hal::Result<std::unique_ptr<FdCanTransport>> connect_unix(const std::string& path);

  hal::Status send(const CanFrame& frame) override;
  hal::Result<bool> receive(CanFrame& frame, hal::TimeUs timeout_us) override;

  int fd() const { return fd_; }

 private:
  // Takes one complete record out of rx_ if there is one.
  hal::Result<bool> pop_frame(CanFrame& frame);

  int fd_;
  std::string name_;
  std::array<std::uint8_t, 64 * kWireFrameBytes> rx_{};
  std::size_t rx_fill_ = 0;
};

}  // namespace cdpr::drivers::can
