#include "drivers/can/last_positions.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace cdpr::drivers::can {
namespace {

bool write_all(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

std::vector<std::optional<std::int64_t>> read_last_positions(const std::string& path, std::size_t winches) {
  std::vector<std::optional<std::int64_t>> counts(winches);
  std::ifstream in(path);
  bool versioned = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "version = 1") versioned = true;
    unsigned long winch = 0;
    long long value = 0;
    if (versioned && std::sscanf(line.c_str(), "winch%lu = %lld", &winch, &value) == 2 && winch < winches) {
      counts[winch] = value;
    }
  }
  return counts;
}

bool write_last_positions(const std::string& path, const std::vector<std::optional<std::int64_t>>& counts,
                          std::string& error) {
  std::string text = "# cdpr-calibd: each winch's last encoder position [counts, unwrapped]; drivers/can/last_positions.h\n"
                     "version = 1\n";
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (counts[i]) text += "winch" + std::to_string(i) + " = " + std::to_string(*counts[i]) + "\n";
  }
  // ".<name>.tmp", as the store names its temp files (it removes stale ones at start).
  const std::size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const std::string temp = (slash == std::string::npos ? std::string() : path.substr(0, slash + 1)) + "." +
                           path.substr(slash == std::string::npos ? 0 : slash + 1) + ".tmp";
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    error = temp + ": " + std::strerror(errno);
    return false;
  }
  const bool written = write_all(fd, text) && ::fsync(fd) == 0;
  const int saved_errno = errno;
  ::close(fd);
  if (!written || ::rename(temp.c_str(), path.c_str()) != 0) {
    error = path + ": " + std::strerror(written ? errno : saved_errno);
    ::unlink(temp.c_str());
    return false;
  }
  if (const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
  return true;
}

}  // namespace cdpr::drivers::can
