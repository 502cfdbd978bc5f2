#include "src/daemon/pose_output_server.h"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>

namespace cdpr::daemon {

hal::Result<std::unique_ptr<PoseOutputServer>> PoseOutputServer::listen(const std::string& path) {
  sockaddr_un address{};
  if (path.size() >= sizeof(address.sun_path)) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "pose output: path too long: " + path);
  }
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return hal::Status(hal::ErrorCode::kIoError, "pose output: socket: " + std::string(std::strerror(errno)));
  ::unlink(path.c_str());
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 || ::chmod(path.c_str(), 0660) != 0 ||
      ::listen(fd, 8) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    return hal::Status(hal::ErrorCode::kIoError, "pose output " + path + ": " + why);
  }
  return std::unique_ptr<PoseOutputServer>(new PoseOutputServer(fd, path));
}

PoseOutputServer::~PoseOutputServer() {
  for (const int client : clients_) ::close(client);
  ::close(fd_);
  ::unlink(path_.c_str());
}

void PoseOutputServer::service() {
  for (;;) {
    const int client = ::accept4(fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (client < 0) break;
    clients_.push_back(client);
  }
  char sink[256];
  for (std::size_t k = 0; k < clients_.size();) {
    const ssize_t n = ::recv(clients_[k], sink, sizeof sink, MSG_DONTWAIT);
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
      ::close(clients_[k]);
      clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(k));
      continue;
    }
    if (n > 0) continue;  // more may wait: read again
    ++k;
  }
}

int PoseOutputServer::broadcast(const std::string& line) {
  int sent = 0;
  for (std::size_t k = 0; k < clients_.size();) {
    const ssize_t n = ::send(clients_[k], line.data(), line.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n != static_cast<ssize_t>(line.size())) {
      // Gone, or not reading: a torn line would garble the stream, so the client goes.
      ::close(clients_[k]);
      clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(k));
      continue;
    }
    ++sent;
    ++k;
  }
  return sent;
}

}  // namespace cdpr::daemon
