#include "drivers/can/fd_can_transport.h"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "drivers/common/posix_status.h"
#include "drivers/common/socket_io.h"

namespace cdpr::drivers::can {

static_assert(sizeof(struct can_frame) == kWireFrameBytes, "wire record is struct can_frame");
static_assert(offsetof(struct can_frame, data) == 8, "wire layout of struct can_frame");

void encode_wire_frame(const CanFrame& frame, std::uint8_t (&out)[kWireFrameBytes]) {
  struct can_frame raw;
  std::memset(&raw, 0, sizeof(raw));
  raw.can_id = frame.id & CAN_SFF_MASK;
  raw.can_dlc = frame.len;
  std::memcpy(raw.data, frame.data.data(), frame.len);
  std::memcpy(out, &raw, sizeof(raw));
}

bool decode_wire_frame(const std::uint8_t* in, CanFrame& frame) {
  struct can_frame raw;
  std::memcpy(&raw, in, sizeof(raw));
  if ((raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0 || raw.can_dlc > CAN_MAX_DLEN ||
      raw.can_id > CAN_SFF_MASK) {
    return false;
  }
  frame.id = raw.can_id;
  frame.len = raw.can_dlc;
  frame.data.fill(0);
  std::memcpy(frame.data.data(), raw.data, raw.can_dlc);
  return true;
}

FdCanTransport::FdCanTransport(int fd, std::string name) : fd_(fd), name_(std::move(name)) {
  set_nonblocking(fd_);
}

FdCanTransport::~FdCanTransport() {
  if (fd_ >= 0) ::close(fd_);
}

hal::Result<std::unique_ptr<FdCanTransport>> FdCanTransport::open_socketcan(const std::string& interface) {
  const std::string device = "socketcan:" + interface;
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int error_number = errno;
    if (error_number == EAFNOSUPPORT || error_number == EPROTONOSUPPORT) {
      return hal::Status(hal::ErrorCode::kUnsupported,
                         device + ": this kernel has no SocketCAN (AF_CAN): " + std::strerror(error_number) +
                             "; load the can/can-raw modules or use the Unix socket transport (unix:<path>)");
    }
    return status_from_errno(error_number, device, "socket(PF_CAN)");
  }
  ifreq request{};
  if (interface.empty() || interface.size() >= sizeof(request.ifr_name)) {
    ::close(fd);
    return hal::Status(hal::ErrorCode::kInvalidArgument, device + ": bad interface name");
  }
  std::memcpy(request.ifr_name, interface.c_str(), interface.size());
  if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
    const int error_number = errno;
    ::close(fd);
    return status_from_errno(error_number, device, "no such interface");
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    const int error_number = errno;
    ::close(fd);
    return status_from_errno(error_number, device, "bind");
  }
  return std::make_unique<FdCanTransport>(fd, device);
}

hal::Result<std::unique_ptr<FdCanTransport>> FdCanTransport::connect_unix(const std::string& path) {
  hal::Result<int> fd = connect_unix_stream(path);
  if (!fd.ok()) return fd.status();
  return std::make_unique<FdCanTransport>(fd.value(), "can-over-unix:" + path);
}

hal::Status FdCanTransport::send(const CanFrame& frame) {
  if (frame.id > kMaxStandardId || frame.len > 8) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, name_ + ": frame id or length out of range");
  }
  std::uint8_t record[kWireFrameBytes];
  encode_wire_frame(frame, record);
  std::size_t sent = 0;
  while (sent < kWireFrameBytes) {
    const ssize_t n = ::send(fd_, record + sent, kWireFrameBytes - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == ENOBUFS)) {
      // Nothing sent: report a full queue rather than block the loop. Part
      // sent (stream only): the record must be completed or the stream
      // desynchronises, so wait briefly for room.
      if (sent == 0) return hal::Status(hal::ErrorCode::kIoError, name_ + ": transmit queue full");
      const hal::Result<bool> ready = wait_writable(fd_, 20'000);
      if (!ready.ok()) return ready.status();
      if (!ready.value()) return hal::Status(hal::ErrorCode::kIoError, name_ + ": stream stalled mid-frame");
      continue;
    }
    return status_from_errno(n < 0 ? errno : EPIPE, name_, "send");
  }
  return hal::Status::Ok();
}

hal::Result<bool> FdCanTransport::pop_frame(CanFrame& frame) {
  if (rx_fill_ < kWireFrameBytes) return false;
  const bool good = decode_wire_frame(rx_.data(), frame);
  std::memmove(rx_.data(), rx_.data() + kWireFrameBytes, rx_fill_ - kWireFrameBytes);
  rx_fill_ -= kWireFrameBytes;
  if (!good) return hal::Status(hal::ErrorCode::kCorruptData, name_ + ": malformed can_frame record");
  return true;
}

hal::Result<bool> FdCanTransport::receive(CanFrame& frame, hal::TimeUs timeout_us) {
  if (rx_fill_ >= kWireFrameBytes) return pop_frame(frame);
  if (timeout_us > 0) {
    const hal::Result<bool> ready = wait_readable(fd_, timeout_us);
    if (!ready.ok()) return ready.status();
    if (!ready.value()) return false;
  }
  for (;;) {
    const ssize_t n = ::read(fd_, rx_.data() + rx_fill_, rx_.size() - rx_fill_);
    if (n > 0) {
      rx_fill_ += static_cast<std::size_t>(n);
      return pop_frame(frame);
    }
    if (n == 0) return hal::Status(hal::ErrorCode::kNotConnected, name_ + ": peer closed the connection");
    if (errno == EINTR) continue;
    if (errno == EAGAIN) return false;
    return status_from_errno(errno, name_, "read");
  }
}

}  // namespace cdpr::drivers::can
