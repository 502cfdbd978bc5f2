#include "src/daemon/control_server.h"

#include <fcntl.h>
#include <grp.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include "src/control/control_request.h"
#include "src/control/control_response.h"

namespace cdpr::daemon {
namespace {

hal::Status errno_status(const std::string& path, const char* operation) {
  return hal::Status(hal::ErrorCode::kIoError,
                     "control socket " + path + ": " + operation + ": " + std::strerror(errno));
}

// Whether something accepts connections at `address` now. Only a refused
// connection (nobody listening) proves a socket file stale.
bool someone_listens(const sockaddr_un& address) {
  const int probe = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (probe < 0) return false;
  const bool refused = connect(probe, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 &&
                       (errno == ECONNREFUSED || errno == ENOENT);
  close(probe);
  return !refused;
}

// A socket file left behind by a crashed daemon is ours to replace; a socket
// somebody still listens on (another daemon) and any other file at the path
// are somebody else's and must not be deleted.
hal::Status remove_stale_socket(const std::string& path, const sockaddr_un& address) {
  struct stat info {};
  if (lstat(path.c_str(), &info) != 0) {
    if (errno == ENOENT) return hal::Status::Ok();
    return errno_status(path, "lstat");
  }
  if (!S_ISSOCK(info.st_mode)) {
    return hal::Status(hal::ErrorCode::kInvalidArgument,
                       "control socket " + path + ": a file that is not a socket is in the way");
  }
  if (someone_listens(address)) {
    return hal::Status(hal::ErrorCode::kInvalidState,
                       "control socket " + path + ": another process is listening on it (a second cdpr-calibd?); "
                       "left alone");
  }
  if (unlink(path.c_str()) != 0) return errno_status(path, "unlink stale socket");
  return hal::Status::Ok();
}

// The group id of `group`: a group name, or the number of a group the
// system knows. A number no group has is refused too: a mistyped id would
// open the socket to whoever is later given that id.
hal::Result<gid_t> group_id(const std::string& path, const std::string& group) {
  std::vector<char> buffer(16384);
  struct group entry {};
  struct group* found = nullptr;
  if (getgrnam_r(group.c_str(), &entry, buffer.data(), buffer.size(), &found) == 0 && found != nullptr) {
    return found->gr_gid;
  }
  if (group.size() <= 9 && group.find_first_not_of("0123456789") == std::string::npos) {
    const auto id = static_cast<gid_t>(std::strtoul(group.c_str(), nullptr, 10));
    if (getgrgid_r(id, &entry, buffer.data(), buffer.size(), &found) == 0 && found != nullptr) return id;
  }
  return hal::Status(hal::ErrorCode::kInvalidArgument,
                     "control socket " + path + ": group '" + group + "' does not exist");
}

// The socket takes the group of the daemon (its primary group, or the
// directory's under a setgid directory) at bind(); chown() is tried only
// when that is not `gid`. Under the shipped unit it cannot succeed: chown is
// filtered (SystemCallFilter=~@privileged) and PrivateUsers= leaves other
// groups unmapped (EINVAL), so the error says how to get the group without it.
hal::Status give_socket_to_group(const std::string& path, gid_t gid, const std::string& group) {
  struct stat info {};
  if (stat(path.c_str(), &info) != 0) return errno_status(path, "stat");
  if (info.st_gid == gid) return hal::Status::Ok();
  if (chown(path.c_str(), static_cast<uid_t>(-1), gid) == 0) return hal::Status::Ok();
  return hal::Status(hal::ErrorCode::kIoError,
                     "control socket " + path + ": it was created with group id " + std::to_string(info.st_gid) +
                         ", [control] group is '" + group + "' and giving it that group failed: chown: " +
                         std::strerror(errno) +
                         "; under systemd make it the daemon's group (a drop-in with Group=" + group +
                         "), see cdpr-calibd.service");
}

}  // namespace

ControlServer::Client::Client(int client_fd, unsigned long long round)
    : fd(client_fd), lines(control::kMaxRequestBytes + 1 /* a "\r" before "\n" is allowed */),
      last_request_round(round) {}

hal::Result<std::unique_ptr<ControlServer>> ControlServer::listen(const std::string& path, Handler handler,
                                                                 unsigned mode, const std::string& group) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(address.sun_path)) {
    return hal::Status(hal::ErrorCode::kInvalidArgument,
                       "control socket path '" + path + "' is empty or longer than " +
                           std::to_string(sizeof(address.sun_path) - 1) + " bytes");
  }
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  std::optional<gid_t> wanted_gid;  // none: the daemon's group, which bind() gives the socket
  if (!group.empty()) {
    const hal::Result<gid_t> resolved = group_id(path, group);
    if (!resolved.ok()) return resolved.status();
    wanted_gid = resolved.value();
  }
  if (hal::Status removed = remove_stale_socket(path, address); !removed.ok()) return removed;

  // Bound, given its group and mode and listening under a name of its own,
  // then renamed into place: the socket appears at `path` ready, so a client
  // (or a unit's ExecStartPost) that sees the file can connect at once. A
  // path too long for the extra suffix is bound where it is.
  const std::string staging = path + kStagingSuffix;
  sockaddr_un bind_address = address;
  const bool staged = staging.size() < sizeof(bind_address.sun_path);
  if (staged) {
    std::memcpy(bind_address.sun_path, staging.c_str(), staging.size() + 1);
    struct stat leftover {};
    if (lstat(staging.c_str(), &leftover) == 0 && S_ISSOCK(leftover.st_mode)) unlink(staging.c_str());
  }
  const std::string& bound_path = staged ? staging : path;

  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return errno_status(path, "socket");
  if (bind(fd, reinterpret_cast<const sockaddr*>(&bind_address), sizeof(bind_address)) != 0) {
    hal::Status status = errno_status(bound_path, "bind");
    close(fd);
    return status;
  }
  // Clients are the robot's operators (group of the socket); nobody else.
  // The group is right before the mode opens the socket to it. The backlog
  // holds a burst of simultaneous connects until the next service().
  hal::Status status = wanted_gid ? give_socket_to_group(bound_path, *wanted_gid, group) : hal::Status::Ok();
  if (status.ok() && chmod(bound_path.c_str(), static_cast<mode_t>(mode)) != 0) {
    status = errno_status(bound_path, "chmod");
  }
  if (status.ok() && ::listen(fd, static_cast<int>(kMaxClients)) != 0) status = errno_status(bound_path, "listen");
  if (status.ok() && staged && rename(staging.c_str(), path.c_str()) != 0) status = errno_status(path, "rename");
  struct stat bound {};
  if (status.ok() && lstat(path.c_str(), &bound) != 0) status = errno_status(path, "lstat");
  if (!status.ok()) {
    close(fd);
    unlink(bound_path.c_str());
    return status;
  }
  return std::unique_ptr<ControlServer>(new ControlServer(fd, path, bound.st_dev, bound.st_ino, std::move(handler)));
}

ControlServer::ControlServer(int listen_fd, std::string path, dev_t device, ino_t inode, Handler handler)
    : listen_fd_(listen_fd), path_(std::move(path)), device_(device), inode_(inode), handler_(std::move(handler)) {}

ControlServer::~ControlServer() {
  for (const auto& client : clients_) close(client->fd);
  close(listen_fd_);
  // Only the file this server bound: if somebody replaced it meanwhile, the
  // path is theirs now.
  struct stat info {};
  if (lstat(path_.c_str(), &info) == 0 && info.st_dev == device_ && info.st_ino == inode_) unlink(path_.c_str());
}

void ControlServer::append_poll_fds(std::vector<pollfd>& fds) const {
  fds.push_back({listen_fd_, POLLIN, 0});
  for (const auto& client : clients_) {
    const bool reading = !client->read_closed && client->output.size() < kReadPauseOutputBytes;
    short events = reading ? POLLIN : 0;
    if (!client->output.empty()) events |= POLLOUT;
    fds.push_back({client->fd, events, 0});
  }
}

void ControlServer::service(const std::vector<pollfd>& fds) {
  ++round_;
  // Start at a rotating entry so that, when the request budget runs out,
  // other clients are first next time.
  std::size_t answered = 0;
  const std::size_t count = fds.size();
  const std::size_t first = count == 0 ? 0 : first_served_++ % count;
  for (std::size_t k = 0; k < count; ++k) {
    const pollfd& entry = fds[(first + k) % count];
    if (entry.revents == 0) continue;
    if (entry.fd == listen_fd_) {
      accept_clients();
      continue;
    }
    const auto it = std::find_if(clients_.begin(), clients_.end(),
                                 [&](const auto& client) { return client->fd == entry.fd; });
    if (it == clients_.end()) continue;
    Client& client = **it;
    if ((entry.revents & (POLLIN | POLLHUP | POLLERR)) && answered < kMaxRequestsPerService &&
        client.output.size() < kReadPauseOutputBytes) {
      answered += read_from(client);
    }
    if (!client.output.empty()) write_to(client);
  }
  std::erase_if(clients_, [](const auto& client) {
    const bool done = client->broken || (client->read_closed && client->output.empty());
    if (done) close(client->fd);
    return done;
  });
}

void ControlServer::accept_clients() {
  // Drain the backlog: several clients may have connected since the last poll.
  for (;;) {
    const int fd = accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;  // EAGAIN (backlog empty) or a transient error: next poll
    if (clients_.size() >= kMaxClients) displace_stalest_client();
    clients_.push_back(std::make_unique<Client>(fd, round_));
    ++counters_.accepted;
  }
}

void ControlServer::displace_stalest_client() {
  const auto stalest = std::min_element(clients_.begin(), clients_.end(), [](const auto& a, const auto& b) {
    return a->last_request_round < b->last_request_round;
  });
  const std::string busy = control::format_error_response(
      "too many control clients: closing this idle connection for a new one; reconnect to continue");
  [[maybe_unused]] const ssize_t ignored = send((*stalest)->fd, busy.data(), busy.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  close((*stalest)->fd);
  clients_.erase(stalest);
  ++counters_.displaced;
}

std::size_t ControlServer::read_from(Client& client) {
  char buffer[kReadChunkBytes];
  // One chunk per service call keeps a chatty client from starving the loop.
  const ssize_t got = recv(client.fd, buffer, sizeof(buffer), 0);
  if (got == 0) {
    client.read_closed = true;
    return 0;
  }
  if (got < 0) {
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) client.broken = true;
    return 0;
  }
  std::size_t answered = 0;
  client.lines.feed(
      std::string_view(buffer, static_cast<std::size_t>(got)),
      [&](std::string_view line) {
        ++counters_.requests;
        ++answered;
        client.last_request_round = round_;
        client.output += handler_(line);
      },
      [&] {
        client.output += control::format_error_response("request longer than " +
                                                        std::to_string(control::kMaxRequestBytes) + " bytes");
      });
  if (client.output.size() > kMaxPendingOutputBytes) {
    client.broken = true;
    ++counters_.dropped;
  }
  return answered;
}

void ControlServer::write_to(Client& client) {
  const ssize_t sent = send(client.fd, client.output.data(), client.output.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  if (sent < 0) {
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      client.broken = true;
      ++counters_.dropped;
    }
    return;
  }
  client.output.erase(0, static_cast<std::size_t>(sent));
}

}  // namespace cdpr::daemon
