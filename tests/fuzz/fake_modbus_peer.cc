#include "fake_modbus_peer.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <pty.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include "../fakes/modbus_crc.h"

namespace cdpr::fuzz {
namespace {

constexpr std::size_t kTcpRequestBytes = 12;  // MBAP header 7 + function 1 + address 2 + count 2
constexpr std::size_t kRtuRequestBytes = 8;   // slave 1 + function 1 + address 2 + count 2 + CRC 2
constexpr int kWaitMs = 1000;                 // longest wait for the driver; far above its timeout

using Clock = std::chrono::steady_clock;

int ms_left(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left > 0 ? static_cast<int>(left) : 0;
}

// Reads up to `count` bytes within kWaitMs; less when the driver hangs up.
std::vector<std::uint8_t> read_request(int fd, std::size_t count) {
  std::vector<std::uint8_t> bytes;
  const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(kWaitMs);
  while (bytes.size() < count) {
    const int wait_ms = ms_left(deadline);
    if (wait_ms == 0) break;
    pollfd entry{fd, POLLIN, 0};
    if (poll(&entry, 1, wait_ms) <= 0 || (entry.revents & POLLIN) == 0) break;
    std::uint8_t buffer[kTcpRequestBytes];
    const ssize_t n = read(fd, buffer, count - bytes.size());
    if (n > 0) {
      bytes.insert(bytes.end(), buffer, buffer + n);
    } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
      break;
    }
  }
  return bytes;
}

void write_all(int fd, const std::vector<std::uint8_t>& bytes) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    const ssize_t n = write(fd, bytes.data() + at, bytes.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the driver already gave up and closed: nothing left to answer
    at += static_cast<std::size_t>(n);
  }
}

}  // namespace

FakeModbusPeer::~FakeModbusPeer() {
  finish();
  if (listen_fd_ >= 0) close(listen_fd_);
}

std::string FakeModbusPeer::start_exchange(ModbusTransport transport, std::vector<std::uint8_t> reply,
                                           bool repair_frame, std::string& error) {
  finish();
  reply_ = std::move(reply);
  request_.clear();
  repair_frame_ = repair_frame;
  if (transport == ModbusTransport::kTcp) {
    if (listen_fd_ < 0) {
      listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
      sockaddr_in address{};
      address.sin_family = AF_INET;
      address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      socklen_t length = sizeof(address);
      if (listen_fd_ < 0 || bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
          ::listen(listen_fd_, 4) != 0 ||
          getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
        error = std::string("loopback Modbus TCP listener: ") + std::strerror(errno);
        if (listen_fd_ >= 0) close(listen_fd_);
        listen_fd_ = -1;
        return "";
      }
      tcp_endpoint_ = "tcp:127.0.0.1:" + std::to_string(ntohs(address.sin_port));
    }
    answering_ = std::thread([this] { answer_tcp(); });
    return tcp_endpoint_;
  }
  char slave[128] = {};
  if (openpty(&pty_master_fd_, &pty_slave_fd_, slave, nullptr, nullptr) != 0) {
    error = std::string("pseudo-terminal for Modbus RTU: ") + std::strerror(errno);
    return "";
  }
  answering_ = std::thread([this] { answer_rtu(); });
  return std::string("rtu:") + slave;
}

void FakeModbusPeer::answer_tcp() {
  pollfd entry{listen_fd_, POLLIN, 0};
  if (poll(&entry, 1, kWaitMs) <= 0) return;
  const int connection = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
  if (connection < 0) return;
  request_ = read_request(connection, kTcpRequestBytes);
  if (repair_frame_ && reply_.size() >= 2 && request_.size() >= 2) {
    reply_[0] = request_[0];  // transaction id
    reply_[1] = request_[1];
  }
  write_all(connection, reply_);
  // End of the reply: a short frame fails at once instead of by timeout.
  shutdown(connection, SHUT_WR);
  // Wait for the driver to close before the socket goes, so it reads what
  // was sent rather than a reset.
  char sink[64];
  const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(kWaitMs);
  for (int wait_ms; (wait_ms = ms_left(deadline)) > 0;) {
    pollfd readable{connection, POLLIN, 0};
    if (poll(&readable, 1, wait_ms) <= 0 || read(connection, sink, sizeof(sink)) <= 0) break;
  }
  close(connection);
}

void FakeModbusPeer::answer_rtu() {
  request_ = read_request(pty_master_fd_, kRtuRequestBytes);
  if (repair_frame_) {
    const std::uint16_t crc = fakes::modbus_crc16(reply_.data(), reply_.size());
    reply_.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    reply_.push_back(static_cast<std::uint8_t>(crc >> 8));
  }
  write_all(pty_master_fd_, reply_);
  // The line stays open until finish(): closing it would hang up the line
  // and discard what the driver has not read yet.
}

void FakeModbusPeer::finish() {
  if (answering_.joinable()) answering_.join();
  for (int* fd : {&pty_master_fd_, &pty_slave_fd_}) {
    if (*fd >= 0) close(*fd);
    *fd = -1;
  }
}

}  // namespace cdpr::fuzz
