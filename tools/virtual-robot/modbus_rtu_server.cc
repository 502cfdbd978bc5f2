#include "virtual-robot/modbus_rtu_server.h"

#include <fcntl.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace cdpr::virtual_robot {
namespace {

constexpr std::uint8_t kBroadcast = 0;

// The frame's length once enough of it is there; 0: not known yet, -1: not
// knowable from the function code (wait for the silence after it).
long expected_frame_bytes(const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < 2) return 0;
  const std::uint8_t function = bytes[1];
  if (function >= 0x01 && function <= 0x06) return 8;  // address, function, 4 data bytes, CRC
  if (function == 0x0F || function == 0x10) return bytes.size() < 7 ? 0 : 9 + static_cast<long>(bytes[6]);
  return -1;
}

}  // namespace

std::uint16_t modbus_rtu_crc(const std::uint8_t* data, std::size_t size) {
  std::uint16_t crc = 0xFFFF;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) != 0 ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001) : crc >> 1;
  }
  return crc;
}

hal::Result<std::unique_ptr<ModbusRtuServer>> ModbusRtuServer::open(const std::string& link_path,
                                                                    VirtualLoadCell& cell) {
  auto server = std::unique_ptr<ModbusRtuServer>(new ModbusRtuServer(link_path, cell));
  if (const hal::Status opened = server->open_pty(); !opened.ok()) return opened;
  return server;
}

ModbusRtuServer::~ModbusRtuServer() { close_pty(); }

hal::Status ModbusRtuServer::open_pty() {
  char name[256];
  if (openpty(&master_, &slave_, name, nullptr, nullptr) != 0) {
    return hal::Status(hal::ErrorCode::kIoError, std::string("openpty: ") + std::strerror(errno));
  }
  termios raw{};
  tcgetattr(slave_, &raw);
  cfmakeraw(&raw);
  tcsetattr(slave_, TCSANOW, &raw);
  fcntl(master_, F_SETFL, fcntl(master_, F_GETFL) | O_NONBLOCK);
  fcntl(master_, F_SETFD, FD_CLOEXEC);
  fcntl(slave_, F_SETFD, FD_CLOEXEC);
  unlink(link_path_.c_str());
  if (symlink(name, link_path_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    close_pty();
    return hal::Status(hal::ErrorCode::kIoError, "link " + link_path_ + " -> " + name + ": " + reason);
  }
  pending_.clear();
  replies_.clear();
  return hal::Status::Ok();
}

void ModbusRtuServer::close_pty() {
  if (master_ >= 0) close(master_);
  if (slave_ >= 0) close(slave_);
  master_ = slave_ = -1;
  unlink(link_path_.c_str());
}

void ModbusRtuServer::append_poll_fds(std::vector<pollfd>& fds) const {
  if (master_ >= 0) fds.push_back({master_, POLLIN, 0});
}

void ModbusRtuServer::handle_frame(const std::uint8_t* frame, std::size_t size, hal::TimeUs now_us) {
  if (size < 4 || modbus_rtu_crc(frame, size - 2) != (frame[size - 2] | frame[size - 1] << 8)) {
    ++dropped_frames_;
    return;
  }
  const std::uint8_t address = frame[0];
  if (address != cell_.options().unit_id && address != kBroadcast) return;  // another device's frame
  if (cell_.fault() == DeviceFault::kSilent) return;
  const std::vector<std::uint8_t> answer = cell_.answer({frame + 1, size - 3});
  if (address == kBroadcast) return;  // executed, never answered
  std::vector<std::uint8_t> reply = {address};
  reply.insert(reply.end(), answer.begin(), answer.end());
  const std::uint16_t crc = modbus_rtu_crc(reply.data(), reply.size());
  reply.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  reply.push_back(static_cast<std::uint8_t>(crc >> 8));
  if (cell_.fault() == DeviceFault::kGarbage) {
    for (std::uint8_t& byte : reply) byte = cell_.noise_byte();
  }
  replies_.push_back({now_us + cell_.options().reply_latency_us, std::move(reply)});
}

void ModbusRtuServer::take_frames(hal::TimeUs now_us, bool gap_passed) {
  for (;;) {
    const long expected = expected_frame_bytes(pending_);
    if (expected > 0 && pending_.size() >= static_cast<std::size_t>(expected)) {
      const bool crc_ok = modbus_rtu_crc(pending_.data(), expected - 2) ==
                          (pending_[expected - 2] | pending_[expected - 1] << 8);
      if (!crc_ok) {
        // Line noise: nothing received with it can be trusted to start a frame.
        ++dropped_frames_;
        pending_.clear();
        return;
      }
      handle_frame(pending_.data(), static_cast<std::size_t>(expected), now_us);
      pending_.erase(pending_.begin(), pending_.begin() + expected);
      continue;
    }
    if (gap_passed && !pending_.empty()) {
      handle_frame(pending_.data(), pending_.size(), now_us);  // the silence ends the frame
      pending_.clear();
    }
    return;
  }
}

void ModbusRtuServer::service(const std::vector<pollfd>& fds, hal::TimeUs now_us) {
  const bool disconnected = cell_.fault() == DeviceFault::kDisconnected;
  if (disconnected && master_ >= 0) close_pty();
  if (!disconnected && master_ < 0 && !open_pty().ok()) close_pty();
  if (master_ < 0) return;
  for (const pollfd& entry : fds) {
    if (entry.fd != master_ || entry.revents == 0) continue;
    std::uint8_t buffer[256];
    for (ssize_t got; (got = read(master_, buffer, sizeof(buffer))) > 0;) {
      pending_.insert(pending_.end(), buffer, buffer + got);
      last_byte_us_ = now_us;
    }
  }
  take_frames(now_us, now_us - last_byte_us_ >= kFrameGapUs);
  while (!replies_.empty() && replies_.front().due_us <= now_us) {
    const std::vector<std::uint8_t>& bytes = replies_.front().bytes;
    if (write(master_, bytes.data(), bytes.size()) < 0 && errno == EAGAIN) break;
    replies_.pop_front();
  }
}

}  // namespace cdpr::virtual_robot
