#pragma once
// The virtual load cell on Modbus TCP (Modbus Messaging on TCP/IP
// Implementation Guide v1.0b): a listening socket on 127.0.0.1, any number
// of clients, MBAP framing by hand (no libmodbus on this side).
//
// As a gateway in front of the transmitter: a request whose unit identifier
// is not the cell's gets exception 0x0B (gateway target device failed to
// respond); a protocol identifier other than 0 or a length field outside
// 2..254 is not Modbus and closes the connection. Each client's bytes are
// gathered until a whole ADU is there; replies wait out the reply latency in
// a queue; a client whose reply no longer fits its socket buffer is dropped.
// Faults: kSilent takes requests and never answers; kGarbage sends noise of
// the reply's length; kDisconnected closes every client and the listening
// socket (connections are refused) until the fault is cleared, when it
// listens again on the same port. Owns its sockets. Not thread-safe.

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "hal/status.h"
#include "virtual-robot/modbus_transport.h"
#include "virtual-robot/virtual_load_cell.h"

namespace cdpr::virtual_robot {

class ModbusTcpServer final : public ModbusTransport {
 public:
  // port 0: any free port (see port()). `cell` must outlive the server.
  static hal::Result<std::unique_ptr<ModbusTcpServer>> listen(int port, VirtualLoadCell& cell);
  ~ModbusTcpServer() override;
  ModbusTcpServer(const ModbusTcpServer&) = delete;
  ModbusTcpServer& operator=(const ModbusTcpServer&) = delete;

  int port() const { return port_; }
  std::string endpoint() const override { return "tcp:127.0.0.1:" + std::to_string(port_); }
  void append_poll_fds(std::vector<pollfd>& fds) const override;
  void service(const std::vector<pollfd>& fds, hal::TimeUs now_us) override;

  std::size_t client_count() const { return clients_.size(); }

 private:
  struct Reply {
    hal::TimeUs due_us;
    std::string bytes;
  };
  struct Client {
    int fd;
    std::string pending;       // bytes of requests not yet whole
    std::deque<Reply> replies;  // answered, waiting out the latency
  };

  ModbusTcpServer(int listen_fd, int port, VirtualLoadCell& cell);
  // Answers the whole ADUs at the front of `client.pending`; false when the
  // client must go (not Modbus).
  bool take_requests(Client& client, hal::TimeUs now_us);
  // Sends the due replies; false when one did not fit.
  bool send_due(Client& client, hal::TimeUs now_us);
  void follow_fault();

  int listen_fd_;
  int port_;
  VirtualLoadCell& cell_;
  std::vector<Client> clients_;
};

}  // namespace cdpr::virtual_robot
