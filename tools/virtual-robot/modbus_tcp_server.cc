#include "virtual-robot/modbus_tcp_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace cdpr::virtual_robot {
namespace {

constexpr std::size_t kMbapBytes = 7;         // transaction (2), protocol (2), length (2), unit (1)
constexpr int kMaxLengthField = 254;          // unit id + a PDU of at most 253 bytes
constexpr std::uint8_t kGatewayTargetFailed = 0x0B;

hal::Result<int> open_listener(int port, int& bound_port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return hal::Status(hal::ErrorCode::kIoError, std::string("socket: ") + std::strerror(errno));
  const int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  if (bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 || ::listen(fd, 8) != 0) {
    const std::string reason = std::strerror(errno);
    close(fd);
    return hal::Status(hal::ErrorCode::kIoError, "Modbus TCP listen on 127.0.0.1:" + std::to_string(port) + ": " + reason);
  }
  socklen_t length = sizeof(address);
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  bound_port = ntohs(address.sin_port);
  return fd;
}

}  // namespace

hal::Result<std::unique_ptr<ModbusTcpServer>> ModbusTcpServer::listen(int port, VirtualLoadCell& cell) {
  int bound_port = 0;
  const hal::Result<int> fd = open_listener(port, bound_port);
  if (!fd.ok()) return fd.status();
  return std::unique_ptr<ModbusTcpServer>(new ModbusTcpServer(fd.value(), bound_port, cell));
}

ModbusTcpServer::ModbusTcpServer(int listen_fd, int port, VirtualLoadCell& cell)
    : listen_fd_(listen_fd), port_(port), cell_(cell) {}

ModbusTcpServer::~ModbusTcpServer() {
  for (const Client& client : clients_) close(client.fd);
  if (listen_fd_ >= 0) close(listen_fd_);
}

void ModbusTcpServer::append_poll_fds(std::vector<pollfd>& fds) const {
  if (listen_fd_ >= 0) fds.push_back({listen_fd_, POLLIN, 0});
  for (const Client& client : clients_) fds.push_back({client.fd, POLLIN, 0});
}

void ModbusTcpServer::follow_fault() {
  const bool disconnected = cell_.fault() == DeviceFault::kDisconnected;
  if (disconnected && listen_fd_ >= 0) {
    for (const Client& client : clients_) close(client.fd);
    clients_.clear();
    close(listen_fd_);
    listen_fd_ = -1;
  } else if (!disconnected && listen_fd_ < 0) {
    int bound_port = 0;
    const hal::Result<int> fd = open_listener(port_, bound_port);
    if (fd.ok()) listen_fd_ = fd.value();  // else: try again next time
  }
}

bool ModbusTcpServer::take_requests(Client& client, hal::TimeUs now_us) {
  std::size_t used = 0;
  while (client.pending.size() - used >= kMbapBytes) {
    const auto* adu = reinterpret_cast<const std::uint8_t*>(client.pending.data() + used);
    const int protocol = adu[2] << 8 | adu[3];
    const int length = adu[4] << 8 | adu[5];
    if (protocol != 0 || length < 2 || length > kMaxLengthField) return false;
    const std::size_t frame = 6 + static_cast<std::size_t>(length);
    if (client.pending.size() - used < frame) break;
    used += frame;
    if (cell_.fault() == DeviceFault::kSilent) continue;
    const std::uint8_t unit = adu[6];
    const std::span<const std::uint8_t> pdu(adu + kMbapBytes, frame - kMbapBytes);
    const std::vector<std::uint8_t> answer =
        unit == cell_.options().unit_id ? cell_.answer(pdu)
                                        : std::vector<std::uint8_t>{static_cast<std::uint8_t>(pdu[0] | 0x80),
                                                                    kGatewayTargetFailed};
    std::string reply(reinterpret_cast<const char*>(adu), 4);  // transaction and protocol echoed
    const std::size_t reply_length = 1 + answer.size();
    reply.push_back(static_cast<char>(reply_length >> 8));
    reply.push_back(static_cast<char>(reply_length & 0xFF));
    reply.push_back(static_cast<char>(unit));
    reply.append(reinterpret_cast<const char*>(answer.data()), answer.size());
    if (cell_.fault() == DeviceFault::kGarbage) {
      for (char& byte : reply) byte = static_cast<char>(cell_.noise_byte());
    }
    client.replies.push_back({now_us + cell_.options().reply_latency_us, std::move(reply)});
  }
  client.pending.erase(0, used);
  return true;
}

bool ModbusTcpServer::send_due(Client& client, hal::TimeUs now_us) {
  while (!client.replies.empty() && client.replies.front().due_us <= now_us) {
    const std::string& bytes = client.replies.front().bytes;
    const ssize_t sent = send(client.fd, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (sent != static_cast<ssize_t>(bytes.size())) return false;
    client.replies.pop_front();
  }
  return true;
}

void ModbusTcpServer::service(const std::vector<pollfd>& fds, hal::TimeUs now_us) {
  follow_fault();
  std::vector<int> closed;
  for (const pollfd& entry : fds) {
    if (entry.revents == 0) continue;
    if (entry.fd == listen_fd_ && listen_fd_ >= 0) {
      for (int fd; (fd = accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC)) >= 0;) {
        clients_.push_back({fd, {}, {}});
      }
      continue;
    }
    const auto client = std::find_if(clients_.begin(), clients_.end(), [&](const Client& c) { return c.fd == entry.fd; });
    if (client == clients_.end()) continue;
    char buffer[512];
    const ssize_t got = recv(client->fd, buffer, sizeof(buffer), 0);
    if (got < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (got > 0) client->pending.append(buffer, static_cast<std::size_t>(got));
    if (got <= 0 || !take_requests(*client, now_us)) closed.push_back(client->fd);
  }
  for (Client& client : clients_) {
    if (!send_due(client, now_us)) closed.push_back(client.fd);
  }
  for (const int fd : closed) {
    if (std::none_of(clients_.begin(), clients_.end(), [fd](const Client& c) { return c.fd == fd; })) continue;
    close(fd);
    std::erase_if(clients_, [fd](const Client& c) { return c.fd == fd; });
  }
}

}  // namespace cdpr::virtual_robot
