#pragma once
// One cdpr-calibd per state directory: an exclusive flock(2) on
// "<state_dir>/cdpr-calibd.lock", taken before the daemon touches the store
// or binds its control socket, and held for the process's life. The kernel
// drops it when the holder exits or is killed, so a crash leaves no stale
// lock behind. The holder writes its pid into the file, so that a second
// instance can say whom it found.
//
// The file is never removed: a removed lock file would let a third instance
// lock a fresh file while the second still holds the old one.
//
// Ownership: owns the lock file's descriptor (close-on-exec); destroying
// the object releases the lock. Not thread-safe (taken once, in main()).

#include <memory>
#include <string>

#include "hal/status.h"

namespace cdpr::daemon {

class InstanceLock {
 public:
  static constexpr const char* kFileName = "cdpr-calibd.lock";

  // Creates `state_dir` when missing, then locks. Errors: kInvalidState
  // when another process holds the lock ("... held by pid 1234"), kIoError
  // when the directory or the file cannot be made or opened; both name the
  // lock file.
  static hal::Result<std::unique_ptr<InstanceLock>> acquire(const std::string& state_dir);
  ~InstanceLock();
  InstanceLock(const InstanceLock&) = delete;
  InstanceLock& operator=(const InstanceLock&) = delete;

  const std::string& path() const { return path_; }

 private:
  InstanceLock(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_;
  std::string path_;
};

}  // namespace cdpr::daemon
