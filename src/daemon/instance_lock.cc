#include "src/daemon/instance_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace cdpr::daemon {
namespace {

hal::Status io_error(const std::string& path, const char* operation) {
  return hal::Status(hal::ErrorCode::kIoError, "lock " + path + ": " + operation + ": " + std::strerror(errno));
}

// The pid the holder wrote, or "" when it has not written one yet (it
// writes right after locking) or the file holds something else.
std::string holder_pid(int fd) {
  char text[32] = {};
  const ssize_t got = pread(fd, text, sizeof(text) - 1, 0);
  if (got <= 0) return {};
  std::string pid(text, static_cast<std::size_t>(got));
  while (!pid.empty() && pid.back() == '\n') pid.pop_back();
  if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) return {};
  return pid;
}

}  // namespace

hal::Result<std::unique_ptr<InstanceLock>> InstanceLock::acquire(const std::string& state_dir) {
  const std::string path = state_dir + "/" + kFileName;
  if (::mkdir(state_dir.c_str(), 0755) != 0 && errno != EEXIST) return io_error(path, "mkdir of its directory");
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return io_error(path, "open");
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    if (error == EWOULDBLOCK) {
      const std::string pid = holder_pid(fd);
      ::close(fd);
      return hal::Status(hal::ErrorCode::kInvalidState,
                         "another cdpr-calibd holds the lock " + path +
                             (pid.empty() ? std::string(" (pid not known yet)") : " (pid " + pid + ")") +
                             ": one daemon per state directory; this one exits and leaves its control socket alone");
    }
    errno = error;
    hal::Status status = io_error(path, "flock");
    ::close(fd);
    return status;
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    hal::Status status = io_error(path, "write pid");
    ::close(fd);
    return status;
  }
  return std::unique_ptr<InstanceLock>(new InstanceLock(fd, path));
}

InstanceLock::~InstanceLock() { ::close(fd_); }

}  // namespace cdpr::daemon
