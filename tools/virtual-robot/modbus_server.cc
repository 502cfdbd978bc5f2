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
  for (const int fd : clients_) close(fd);
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
  for (const int fd : clients_) fds.push_back({fd, POLLIN, 0});
}

void ModbusServer::service(const std::vector<pollfd>& fds) {
  std::vector<int> closed;
  for (const pollfd& entry : fds) {
    if (entry.revents == 0) continue;
    if (entry.fd == listen_fd_) {
      for (int fd; (fd = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC)) >= 0;) clients_.push_back(fd);
      continue;
    }
    if (std::find(clients_.begin(), clients_.end(), entry.fd) == clients_.end()) continue;
    // The request has arrived (readable): modbus_receive reads it whole.
    std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
    modbus_set_socket(context_, entry.fd);
    const int length = modbus_receive(context_, query);
    if (length < 0) {
      closed.push_back(entry.fd);
      continue;
    }
    if (length == 0 || mute_) continue;  // not for us, or muted
    ++requests_;
    if (modbus_reply(context_, query, length, mapping_) < 0) closed.push_back(entry.fd);
  }
  for (const int fd : closed) {
    close(fd);
    std::erase(clients_, fd);
  }
}

}  // namespace cdpr::virtual_robot
