#pragma once
// The virtual robot's load cell: a real Modbus TCP server (libmodbus) on
// 127.0.0.1 serving the register map of drivers/modbus/tension_registers.h
// at address 0, as both holding and input registers (function 0x03 and
// 0x04), for any number of clients.
//
// It runs on the virtual robot's physics thread, so nothing here may wait
// for a client: sockets are non-blocking, each client's bytes are gathered
// until a whole request (MBAP header + its length) is there and only then
// handed to libmodbus to answer (libmodbus' own receive would wait up to its
// byte timeout per byte for a client that sends slowly), and a client that
// does not read its replies is dropped when one no longer fits its socket
// buffer (libmodbus' send would block). A header announcing an impossible
// length drops the client too. Owns its libmodbus context and sockets.
// Not thread-safe.

#include <poll.h>

#include <memory>
#include <string>
#include <vector>

#include "drivers/modbus/tension_registers.h"
#include "hal/status.h"

typedef struct _modbus modbus_t;                // NOLINT: libmodbus' opaque types
typedef struct _modbus_mapping_t modbus_mapping_t;  // NOLINT

namespace cdpr::virtual_robot {

class ModbusServer {
 public:
  // port 0: any free port (see port()).
  static hal::Result<std::unique_ptr<ModbusServer>> listen(int port, int slave_id,
                                                          drivers::modbus::WordOrder order);
  ~ModbusServer();
  ModbusServer(const ModbusServer&) = delete;
  ModbusServer& operator=(const ModbusServer&) = delete;

  int port() const { return port_; }
  // What the next replies carry.
  void set_value(const drivers::modbus::TensionRegisters& value);
  // While set, requests are read but not answered (a load cell gone silent).
  void set_mute(bool mute) { mute_ = mute; }

  void append_poll_fds(std::vector<pollfd>& fds) const;
  // Accepts, reads what is ready and answers every whole request. Never blocks.
  void service(const std::vector<pollfd>& fds);

  unsigned long long requests() const { return requests_; }
  std::size_t client_count() const { return clients_.size(); }

 private:
  ModbusServer(modbus_t* context, modbus_mapping_t* mapping, int listen_fd, int port,
               drivers::modbus::WordOrder order);

  modbus_t* context_;
  modbus_mapping_t* mapping_;
  int listen_fd_;
  int port_;
  drivers::modbus::WordOrder order_;
  // Answers the whole requests at the front of `client.pending`; false when
  // the client must go (garbage header, reply did not fit).
  struct Client {
    int fd;
    std::string pending;  // bytes of requests not yet whole
  };
  bool answer_whole_requests(Client& client);

  std::vector<Client> clients_;
  bool mute_ = false;
  unsigned long long requests_ = 0;
};

}  // namespace cdpr::virtual_robot
