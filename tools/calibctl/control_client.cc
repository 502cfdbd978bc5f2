#include "calibctl/control_client.h"

#include <grp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace cdpr::calibctl {

ControlClient::~ControlClient() {
  if (fd_ >= 0) close(fd_);
}

bool ControlClient::connect(const std::string& socket_path, std::string& error) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (socket_path.size() >= sizeof(address.sun_path)) {
    error = "socket path too long: " + socket_path;
    return false;
  }
  std::memcpy(address.sun_path, socket_path.c_str(), socket_path.size() + 1);
  fd_ = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0 || ::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    error = connect_error(socket_path, errno);
    return false;
  }
  return true;
}

std::string connect_error(const std::string& socket_path, int error_number) {
  const std::string failed = "cannot connect to " + socket_path + ": ";
  if (error_number == EACCES || error_number == EPERM) {
    // Mode 0660: the daemon's user and the socket's group may connect.
    struct stat info {};
    if (stat(socket_path.c_str(), &info) != 0) {
      return failed + "permission denied: its directory is closed to you (the daemon's runtime directory; "
                      "see [control] group in cdpr-calibd.toml)";
    }
    const group* owner_group = getgrgid(info.st_gid);
    const std::string name = owner_group ? owner_group->gr_name : std::to_string(info.st_gid);
    return failed + "permission denied: only members of group '" + name +
           "' may control cdpr-calibd (ask to be added: usermod -aG " + name + " <user>, then log in again)";
  }
  std::string text = failed + std::strerror(error_number);
  if (error_number == ENOENT || error_number == ECONNREFUSED) text += " (is cdpr-calibd running?)";
  return text;
}

bool ControlClient::request(const std::string& request, std::string& response, std::string& error, int timeout_ms) {
  const std::string line = request + "\n";
  std::size_t sent = 0;
  while (sent < line.size()) {
    const ssize_t n = send(fd_, line.data() + sent, line.size() - sent, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      error = std::string("send: ") + std::strerror(errno);
      return false;
    }
    sent += static_cast<std::size_t>(n);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const std::size_t newline = buffered_.find('\n');
    if (newline != std::string::npos) {
      response = buffered_.substr(0, newline);
      buffered_.erase(0, newline + 1);
      return true;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      error = "no response from the daemon within " + std::to_string(timeout_ms) + " ms";
      return false;
    }
    pollfd entry{fd_, POLLIN, 0};
    if (poll(&entry, 1, static_cast<int>(left.count())) < 0 && errno != EINTR) {
      error = std::string("poll: ") + std::strerror(errno);
      return false;
    }
    if (!(entry.revents & (POLLIN | POLLHUP | POLLERR))) continue;
    char buffer[4096];
    const ssize_t got = recv(fd_, buffer, sizeof(buffer), 0);
    if (got == 0) {
      error = "the daemon closed the connection";
      return false;
    }
    if (got < 0) {
      if (errno == EINTR) continue;
      error = std::string("recv: ") + std::strerror(errno);
      return false;
    }
    buffered_.append(buffer, static_cast<std::size_t>(got));
  }
}

}  // namespace cdpr::calibctl
