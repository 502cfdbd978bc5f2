#pragma once
// The pose from the cables for the robot's controller ([operation]
// pose_output = "unix:<path>"): a Unix stream socket the daemon listens
// on; every client gets every line broadcast from then on
// (src/operation/pose_output_line.h). One-way: what a client sends is
// read and dropped. A client that cannot take a line at once (its buffer
// full: it does not read) is dropped, never waited for: the loop does not
// block on a controller. Not thread-safe (the loop thread).

#include <string>
#include <vector>

#include "hal/status.h"

namespace cdpr::daemon {

class PoseOutputServer {
 public:
  // Binds `path` (a stale socket file there is replaced), mode 0660.
  static hal::Result<std::unique_ptr<PoseOutputServer>> listen(const std::string& path);
  ~PoseOutputServer();
  PoseOutputServer(const PoseOutputServer&) = delete;
  PoseOutputServer& operator=(const PoseOutputServer&) = delete;

  // Takes new clients and drains what they sent; never blocks.
  void service();
  // Sends `line` to every client; returns how many took it whole.
  int broadcast(const std::string& line);
  int clients() const { return static_cast<int>(clients_.size()); }

 private:
  PoseOutputServer(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_;
  std::string path_;
  std::vector<int> clients_;
};

}  // namespace cdpr::daemon
