#include "virtual-robot/modbus_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace cdpr::virtual_robot {

hal::Result<std::unique_ptr<ModbusServer>> ModbusServer::listen(int port, int slave_id,
                                                              drivers::modbus::WordOrder order) {
  modbus_t* context = modbus_new_tcp("127.0.0.1", port);
  if (context == nullptr) return hal::Status(hal::ErrorCode::kIoError, "modbus_new_tcp failed");
  modbus_set_slave(context, slave_id);
  const int fd = modbus_tcp_listen(context, 8);
  if (fd < 0) {
    const std::string reason = modbus_strerror(errno);
    modbus_free(context);
    return hal::Status(hal::ErrorCode::kIoError, "Modbus TCP listen on 127.0.0.1:" + std::to_string(port) + ": " + reason);
  }
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
  sockaddr_in bound{};
  socklen_t length = sizeof(bound);
  getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &length);
  modbus_mapping_t* mapping =
      modbus_mapping_new(0, 0, drivers::modbus::kTensionRegisterCount, drivers::modbus::kTensionRegisterCount);
  return std::unique_ptr<ModbusServer>(new ModbusServer(context, mapping, fd, ntohs(bound.sin_port), order));
}

ModbusServer::ModbusServer(modbus_t* context, modbus_mapping_t* mapping, int listen_fd, int port,
                           drivers::modbus::WordOrder order)
    : context_(context), mapping_(mapping), listen_fd_(listen_fd), port_(port), order_(order) {}

ModbusServer::~ModbusServer() {
  for (const Client& client : clients_) close(client.fd);
  close(listen_fd_);
  modbus_mapping_free(mapping_);
  modbus_free(context_);  // its socket is one of the clients, already closed
}

void ModbusServer::set_value(const drivers::modbus::TensionRegisters& value) {
  std::uint16_t registers[drivers::modbus::kTensionRegisterCount];
  drivers::modbus::encode_tension_registers(value, order_, registers);
  std::copy(std::begin(registers), std::end(registers), mapping_->tab_registers);
  std::copy(std::begin(registers), std::end(registers), mapping_->tab_input_registers);
}

void ModbusServer::append_poll_fds(std::vector<pollfd>& fds) const {
  fds.push_back({listen_fd_, POLLIN, 0});
  for (const Client& client : clients_) fds.push_back({client.fd, POLLIN, 0});
}

bool ModbusServer::answer_whole_requests(Client& client) {
  // MBAP header: transaction id (2), protocol id (2), length (2) of what
  // follows it: unit id, function, data.
  constexpr std::size_t kLengthFieldEnd = 6;
  std::size_t used = 0;
  while (client.pending.size() - used >= kLengthFieldEnd) {
    const auto* header = reinterpret_cast<const std::uint8_t*>(client.pending.data() + used);
    const std::size_t frame = kLengthFieldEnd + ((header[4] << 8) | header[5]);
    if (frame < kLengthFieldEnd + 2 || frame > MODBUS_TCP_MAX_ADU_LENGTH) return false;
    if (client.pending.size() - used < frame) break;
    if (!mute_) {
      ++requests_;
      modbus_set_socket(context_, client.fd);
      if (modbus_reply(context_, header, static_cast<int>(frame), mapping_) < 0) return false;
    }
    used += frame;
  }
  client.pending.erase(0, used);
  return true;
}

void ModbusServer::service(const std::vector<pollfd>& fds) {
  std::vector<int> closed;
  for (const pollfd& entry : fds) {
    if (entry.revents == 0) continue;
    if (entry.fd == listen_fd_) {
      for (int fd; (fd = accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC)) >= 0;) {
        clients_.push_back({fd, {}});
      }
      continue;
    }
    const auto client = std::find_if(clients_.begin(), clients_.end(),
                                     [&](const Client& c) { return c.fd == entry.fd; });
    if (client == clients_.end()) continue;
    char buffer[MODBUS_TCP_MAX_ADU_LENGTH];
    const ssize_t got = recv(client->fd, buffer, sizeof(buffer), 0);
    if (got < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (got > 0) client->pending.append(buffer, static_cast<std::size_t>(got));
    if (got <= 0 || !answer_whole_requests(*client)) closed.push_back(client->fd);
  }
  for (const int fd : closed) {
    close(fd);
    std::erase_if(clients_, [fd](const Client& c) { return c.fd == fd; });
  }
}

}  // namespace cdpr::virtual_robot
