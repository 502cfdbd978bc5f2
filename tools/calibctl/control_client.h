#pragma once
// calibctl's side of the control socket (src/control/control_request.h):
// connect to the daemon's Unix stream socket, send one request line, read
// the one response line. Blocking with a timeout; one connection serves any
// number of requests in turn (status --follow). Owns its socket.

#include <string>

namespace cdpr::calibctl {

class ControlClient {
 public:
  ControlClient() = default;
  ~ControlClient();
  ControlClient(const ControlClient&) = delete;
  ControlClient& operator=(const ControlClient&) = delete;

  // false with `error` set (connect_error below).
  bool connect(const std::string& socket_path, std::string& error);
  // Sends `request` (a "\n" is appended) and waits at most timeout_ms for
  // the response line, returned without its "\n". false with `error` set
  // on timeout, a closed connection or an i/o error.
  bool request(const std::string& request, std::string& response, std::string& error, int timeout_ms = 10'000);

 private:
  int fd_ = -1;
  std::string buffered_;  // bytes after the last response line
};

// Why connecting to `socket_path` failed with `error_number`, for the
// operator: a permission error names the group that may control the daemon;
// only a missing socket or a refused connection suggests the daemon is not
// running.
std::string connect_error(const std::string& socket_path, int error_number);

}  // namespace cdpr::calibctl
