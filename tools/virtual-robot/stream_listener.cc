#include "virtual-robot/stream_listener.h"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace cdpr::virtual_robot {

hal::Result<std::unique_ptr<StreamListener>> StreamListener::listen(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.size() >= sizeof(address.sun_path)) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "socket path too long: " + path);
  }
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  unlink(path.c_str());
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0 || bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 ||
      ::listen(fd, 8) != 0) {
    const std::string reason = std::strerror(errno);
    if (fd >= 0) close(fd);
    return hal::Status(hal::ErrorCode::kIoError, path + ": " + reason);
  }
  return std::unique_ptr<StreamListener>(new StreamListener(fd, path));
}

StreamListener::~StreamListener() {
  for (const int fd : clients_) close(fd);
  close(listen_fd_);
  unlink(path_.c_str());
}

void StreamListener::append_poll_fds(std::vector<pollfd>& fds) const {
  fds.push_back({listen_fd_, POLLIN, 0});
  for (const int fd : clients_) fds.push_back({fd, POLLIN, 0});
}

void StreamListener::service(const std::vector<pollfd>& fds, const OnBytes& on_bytes) {
  std::vector<int> closed;
  for (const pollfd& entry : fds) {
    if (entry.revents == 0) continue;
    if (entry.fd == listen_fd_) {
      for (int fd; (fd = accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC)) >= 0;) {
        clients_.push_back(fd);
      }
      continue;
    }
    if (std::find(clients_.begin(), clients_.end(), entry.fd) == clients_.end()) continue;
    char buffer[4096];
    const ssize_t got = recv(entry.fd, buffer, sizeof(buffer), 0);
    if (got > 0) {
      on_bytes(entry.fd, std::string_view(buffer, static_cast<std::size_t>(got)));
    } else if (got == 0 || (errno != EAGAIN && errno != EINTR)) {
      closed.push_back(entry.fd);
    }
  }
  for (const int fd : closed) {
    close(fd);
    std::erase(clients_, fd);
  }
}

void StreamListener::broadcast(std::string_view bytes) {
  std::vector<int> broken;
  for (const int fd : clients_) {
    const ssize_t sent = send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (sent == static_cast<ssize_t>(bytes.size())) continue;
    if (sent < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      ++dropped_writes_;
    } else {
      broken.push_back(fd);
    }
  }
  for (const int fd : broken) {
    close(fd);
    std::erase(clients_, fd);
  }
}

}  // namespace cdpr::virtual_robot
