#pragma once
// The daemon's control socket: a Unix stream socket (mode 0660, e.g.
// /run/cdpr-calib/control) serving many clients at once without ever
// blocking the daemon loop. Each client sends request lines
// (src/control/control_request.h); the handler answers each with one
// response line, written back in order.
//
// Integration: the owner's event loop asks for the descriptors to watch
// (append_poll_fds), calls poll() with its own timeout together with its other
// descriptors, then hands the results back (service). Everything is
// non-blocking; a slow or dead client only costs its own connection.
//
// Bounds (a client can never make the daemon buffer without limit, nor
// stall its loop): requests are cut by LineAssembler (an overlong line gets
// an error response and is skipped); at most kMaxClients connections: when
// full, a new client displaces the one whose last complete request (or
// connect) is oldest, which is told why and closed, so idle or slow-loris
// connections cannot lock operators out; at most kMaxPendingOutputBytes
// unsent response bytes per client (a client that does not read is dropped);
// one service() call reads at most kReadChunkBytes per client and stops
// reading once kMaxRequestsPerService requests were answered (the rest wait
// in the kernel for the next call; the first client served rotates), so the
// loop's time per call stays bounded however hard clients push.
//
// Access: the socket gets `mode` (0660: owner and group) and the group it is
// created with: the daemon's primary group (or a setgid directory's). A
// `group` given is checked against it and, only when it differs, set with
// chown(), which the shipped unit forbids (its seccomp filter, and
// PrivateUsers= maps no other group): under systemd the group comes from
// the unit's Group= instead (cdpr-calibd.service).
//
// Ownership: owns its listening and client sockets; the destructor closes
// them and removes the socket file it bound, and only that file (same device
// and inode): never a socket another process put at the path since. Not thread-safe: one thread
// (the daemon loop) calls everything, and the handler runs on that thread.

#include <poll.h>
#include <sys/types.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hal/status.h"
#include "src/control/line_assembler.h"

namespace cdpr::daemon {

class ControlServer {
 public:
  static constexpr std::size_t kMaxClients = 128;
  // The socket is bound under its path plus this, then renamed into place (listen()).
  static constexpr const char* kStagingSuffix = ".binding";
  static constexpr std::size_t kMaxPendingOutputBytes = 1 << 20;
  // A client with this much of its answers unread gets no more requests
  // read until it has read them (backpressure): a pipelining client is
  // answered in full at its own pace, and only one whose answers pile up
  // regardless passes kMaxPendingOutputBytes and is dropped.
  static constexpr std::size_t kReadPauseOutputBytes = 64 << 10;
  static constexpr std::size_t kReadChunkBytes = 1024;
  static constexpr std::size_t kMaxRequestsPerService = 256;

  // Answers one request line (without its "\n") with one response line
  // (with its "\n").
  using Handler = std::function<std::string(std::string_view request_line)>;

  // Binds and listens at `path` (a stale socket left by a crash, one nobody
  // listens on, is removed; a live one or any other file there is refused
  // and left alone), sets its mode to `mode` and, when `group` (a name or a
  // numeric id) is not empty and not already the socket's group, its group.
  // Errors: kInvalidArgument (path too long, not a socket in the way, no
  // such group), kInvalidState (another process listens there), kIoError
  // (socket, bind, stat, chown, chmod, listen, lstat), each naming the path
  // and errno.
  static hal::Result<std::unique_ptr<ControlServer>> listen(const std::string& path, Handler handler,
                                                           unsigned mode = 0660, const std::string& group = "");
  ~ControlServer();
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  // Appends the listening socket and every client (POLLIN, plus POLLOUT when
  // it has unsent output).
  void append_poll_fds(std::vector<pollfd>& fds) const;
  // Accepts, reads, answers and writes for every entry of `fds` that is
  // ours and ready (entries of other owners are ignored), then drops closed
  // clients. Never blocks.
  void service(const std::vector<pollfd>& fds);

  std::size_t client_count() const { return clients_.size(); }
  const std::string& path() const { return path_; }

  // Counters for diagnostics.
  struct Counters {
    unsigned long long accepted = 0;
    unsigned long long displaced = 0;  // closed to make room for a new client (kMaxClients)
    unsigned long long requests = 0;
    unsigned long long dropped = 0;  // output over the limit or i/o error
  };
  const Counters& counters() const { return counters_; }

 private:
  struct Client {
    int fd = -1;
    control::LineAssembler lines;
    std::string output;      // responses not yet written
    bool read_closed = false;  // peer sent EOF: close once output is flushed
    bool broken = false;       // close now
    unsigned long long last_request_round = 0;  // service() call of the last complete request or the connect
    explicit Client(int client_fd, unsigned long long round);
  };

  ControlServer(int listen_fd, std::string path, dev_t device, ino_t inode, Handler handler);
  void accept_clients();
  // Closes the client whose last request is oldest, telling it why.
  void displace_stalest_client();
  // Returns the number of requests answered.
  std::size_t read_from(Client& client);
  void write_to(Client& client);

  int listen_fd_;
  std::string path_;
  dev_t device_;  // of the socket file bound, so that only that file is removed
  ino_t inode_;
  Handler handler_;
  std::vector<std::unique_ptr<Client>> clients_;
  Counters counters_;
  unsigned long long round_ = 0;   // service() calls so far: the clients' idea of age, no clock needed
  std::size_t first_served_ = 0;   // rotates so that a busy call does not always favour the same clients
};

}  // namespace cdpr::daemon
