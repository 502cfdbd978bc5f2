#pragma once
// A Unix stream socket that any number of clients connect to, for the
// virtual robot's CAN and pose servers: broadcast bytes to every client,
// and hand each client's received bytes to a callback. Non-blocking
// throughout: a client that does not keep up loses what does not fit its
// socket buffer (counted), as a frame lost on a bus; a closed client is
// dropped. Owns its sockets; removes its path when destroyed.
// Not thread-safe: one thread (the virtual robot's loop).

#include <poll.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hal/status.h"

namespace cdpr::virtual_robot {

class StreamListener {
 public:
  // Bytes from client `client_id` (stable while it stays connected).
  using OnBytes = std::function<void(int client_id, std::string_view bytes)>;

  static hal::Result<std::unique_ptr<StreamListener>> listen(const std::string& path);
  ~StreamListener();
  StreamListener(const StreamListener&) = delete;
  StreamListener& operator=(const StreamListener&) = delete;

  void append_poll_fds(std::vector<pollfd>& fds) const;
  // Accepts and reads what is ready in `fds` (others' entries ignored).
  void service(const std::vector<pollfd>& fds, const OnBytes& on_bytes);
  // Sends `bytes` to every client; a client whose buffer is full misses them
  // (whole writes only: a partial write drops that client, since its stream
  // would be out of step).
  void broadcast(std::string_view bytes);

  std::size_t client_count() const { return clients_.size(); }
  unsigned long long dropped_writes() const { return dropped_writes_; }

 private:
  StreamListener(int fd, std::string path) : listen_fd_(fd), path_(std::move(path)) {}

  int listen_fd_;
  std::string path_;
  std::vector<int> clients_;
  unsigned long long dropped_writes_ = 0;
};

}  // namespace cdpr::virtual_robot
