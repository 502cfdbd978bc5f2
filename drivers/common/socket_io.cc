#include "drivers/common/socket_io.h"

#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

#include "drivers/common/posix_status.h"

namespace cdpr::drivers {
namespace {

// poll() takes milliseconds: round up so a 1 us timeout still waits.
int timeout_ms(hal::TimeUs timeout_us) {
  if (timeout_us <= 0) return 0;
  const hal::TimeUs ms = (timeout_us + 999) / 1000;
  return ms > 1'000'000'000 ? 1'000'000'000 : static_cast<int>(ms);
}

hal::Result<bool> wait_for(int fd, short events, hal::TimeUs timeout_us) {
  pollfd pfd{fd, events, 0};
  for (;;) {
    const int n = ::poll(&pfd, 1, timeout_ms(timeout_us));
    if (n > 0) return true;  // ready, or error/hangup that the next read/write reports
    if (n == 0) return false;
    if (errno != EINTR) return status_from_errno(errno, "socket", "poll");
  }
}

}  // namespace

bool set_nonblocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL, 0);
  return flags >= 0 && ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) == 0;
}

hal::Result<bool> wait_readable(int fd, hal::TimeUs timeout_us) { return wait_for(fd, POLLIN, timeout_us); }
hal::Result<bool> wait_writable(int fd, hal::TimeUs timeout_us) { return wait_for(fd, POLLOUT, timeout_us); }

hal::Result<int> connect_unix_stream(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(address.sun_path)) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "unix socket path empty or too long: '" + path + "'");
  }
  std::memcpy(address.sun_path, path.data(), path.size());
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return status_from_errno(errno, "unix:" + path, "socket");
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 || !set_nonblocking(fd)) {
    const int error_number = errno;
    ::close(fd);
    return status_from_errno(error_number, "unix:" + path, "connect");
  }
  return fd;
}

hal::Result<int> connect_tcp(const std::string& host, int port, hal::TimeUs timeout_us) {
  const std::string device = "tcp:" + host + ":" + std::to_string(port);
  if (port <= 0 || port > 65535) return hal::Status(hal::ErrorCode::kInvalidArgument, device + ": bad port");
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0) {
    return hal::Status(hal::ErrorCode::kNotConnected, device + ": resolve: " + ::gai_strerror(rc));
  }
  hal::Status last(hal::ErrorCode::kNotConnected, device + ": no address");
  for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
    if (fd < 0) {
      last = status_from_errno(errno, device, "socket");
      continue;
    }
    if (::connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
      ::freeaddrinfo(found);
      return fd;
    }
    if (errno == EINPROGRESS) {
      const hal::Result<bool> ready = wait_writable(fd, timeout_us);
      int so_error = 0;
      socklen_t length = sizeof(so_error);
      if (ready.ok() && ready.value() && ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &length) == 0 &&
          so_error == 0) {
        ::freeaddrinfo(found);
        return fd;
      }
      last = !ready.ok()           ? ready.status()
             : !ready.value()      ? hal::Status(hal::ErrorCode::kTimeout, device + ": connect timed out")
                                   : status_from_errno(so_error, device, "connect");
    } else {
      last = status_from_errno(errno, device, "connect");
    }
    ::close(fd);
  }
  ::freeaddrinfo(found);
  return last;
}

hal::Result<int> connect_endpoint(std::string_view endpoint, hal::TimeUs timeout_us) {
  if (endpoint.starts_with("unix:")) return connect_unix_stream(std::string(endpoint.substr(5)));
  if (endpoint.starts_with("tcp:")) {
    const std::string_view rest = endpoint.substr(4);
    const std::size_t colon = rest.rfind(':');
    int port = 0;
    if (colon != std::string_view::npos) {
      const std::string_view digits = rest.substr(colon + 1);
      const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
      if (ec == std::errc() && end == digits.data() + digits.size()) {
        return connect_tcp(std::string(rest.substr(0, colon)), port, timeout_us);
      }
    }
  }
  return hal::Status(hal::ErrorCode::kInvalidArgument,
                     "endpoint '" + std::string(endpoint) + "': expected unix:<path> or tcp:<host>:<port>");
}

hal::Result<int> start_connect_endpoint(std::string_view endpoint) {
  const std::string device(endpoint);
  if (endpoint.starts_with("unix:")) {
    const std::string path(endpoint.substr(5));
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    if (path.empty() || path.size() >= sizeof(address.sun_path)) {
      return hal::Status(hal::ErrorCode::kInvalidArgument, "unix socket path empty or too long: '" + path + "'");
    }
    std::memcpy(address.sun_path, path.data(), path.size());
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd < 0) return status_from_errno(errno, device, "socket");
    if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
      const int error_number = errno;
      ::close(fd);
      return status_from_errno(error_number, device, "connect");
    }
    return fd;
  }
  const std::string_view rest = endpoint.starts_with("tcp:") ? endpoint.substr(4) : std::string_view();
  const std::size_t colon = rest.rfind(':');
  if (rest.empty() || colon == std::string_view::npos || colon == 0 || colon + 1 == rest.size()) {
    return hal::Status(hal::ErrorCode::kInvalidArgument,
                       "endpoint '" + device + "': expected unix:<path> or tcp:<host>:<port>");
  }
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string host(rest.substr(0, colon));
  const std::string service(rest.substr(colon + 1));
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0) {
    return hal::Status(hal::ErrorCode::kNotConnected, device + ": resolve: " + ::gai_strerror(rc));
  }
  const int fd = ::socket(found->ai_family, found->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, found->ai_protocol);
  if (fd < 0) {
    ::freeaddrinfo(found);
    return status_from_errno(errno, device, "socket");
  }
  const int rc = ::connect(fd, found->ai_addr, found->ai_addrlen);
  const int error_number = errno;
  ::freeaddrinfo(found);
  if (rc != 0 && error_number != EINPROGRESS) {
    ::close(fd);
    return status_from_errno(error_number, device, "connect");
  }
  return fd;
}

hal::Result<bool> connect_progress(int fd, const std::string& device) {
  const hal::Result<bool> writable = wait_writable(fd, 0);
  if (!writable.ok()) return writable.status();
  if (!writable.value()) return false;
  int so_error = 0;
  socklen_t length = sizeof(so_error);
  if (::getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &length) != 0) return status_from_errno(errno, device, "connect");
  if (so_error != 0) return status_from_errno(so_error, device, "connect");
  return true;
}

}  // namespace cdpr::drivers
