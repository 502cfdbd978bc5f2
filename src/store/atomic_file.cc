#include "src/store/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

namespace cdpr::store {
namespace {

// Closes on every path out of a function.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  // close() reports deferred write errors (NFS, quota); callers that wrote must check it.
  bool close() {
    const int fd = fd_;
    fd_ = -1;
    return ::close(fd) == 0;
  }

 private:
  int fd_;
};

bool write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t written = ::write(fd, bytes.data(), bytes.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    bytes.remove_prefix(static_cast<std::size_t>(written));
  }
  return true;
}

}  // namespace

bool crash_requested(const CrashHook& hook, int step) { return hook && hook(step); }

StoreError simulated_crash(const std::string& path, int step) {
  return StoreError{"crash", path, 0, "simulated crash after step " + std::to_string(step)};
}

std::string temp_name(const std::string& name) { return "." + name + ".tmp"; }

StoreResult<Done> write_file_atomically(const std::string& dir, const std::string& name, std::string_view content,
                                        const CrashHook& hook, int first_step) {
  const std::string temp_path = dir + "/" + temp_name(name);
  const std::string final_path = dir + "/" + name;
  FileDescriptor file(::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (file.get() < 0) return Unexpected{errno_error("open", temp_path)};
  // A real failure (a full disk, EIO) removes the temp file: a full disk
  // keeps no half-written files, and the old file is untouched. A simulated
  // crash leaves everything as a kill would.
  const auto failed = [&](const char* operation) {
    StoreError error = errno_error(operation, temp_path);
    ::unlink(temp_path.c_str());
    return Unexpected{std::move(error)};
  };

  const std::size_t half = content.size() / 2;
  if (!write_all(file.get(), content.substr(0, half))) return failed("write");
  if (crash_requested(hook, first_step)) return Unexpected{simulated_crash(temp_path, first_step)};
  if (!write_all(file.get(), content.substr(half))) return failed("write");
  if (crash_requested(hook, first_step + 1)) return Unexpected{simulated_crash(temp_path, first_step + 1)};

  if (::fsync(file.get()) != 0) return failed("fsync");
  if (!file.close()) return failed("close");
  if (crash_requested(hook, first_step + 2)) return Unexpected{simulated_crash(temp_path, first_step + 2)};

  if (::rename(temp_path.c_str(), final_path.c_str()) != 0) return failed("rename");
  const int renamed_step = first_step + kAtomicRenameStepOffset;
  if (crash_requested(hook, renamed_step)) return Unexpected{simulated_crash(final_path, renamed_step)};

  const auto synced = fsync_directory(dir);
  if (!synced) return synced;
  if (crash_requested(hook, first_step + 4)) return Unexpected{simulated_crash(dir, first_step + 4)};
  return Done{};
}

StoreResult<Done> fsync_directory(const std::string& dir) {
  FileDescriptor directory(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (directory.get() < 0) return Unexpected{errno_error("open", dir)};
  if (::fsync(directory.get()) != 0) return Unexpected{errno_error("fsync", dir)};
  return Done{};
}

StoreResult<Done> probe_writable(const std::string& dir) {
  const std::string path = dir + "/" + temp_name("write-probe");
  FileDescriptor file(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (file.get() < 0) return Unexpected{errno_error("open", path)};
  // A few bytes, so that a full disk or a failing device shows here, not at the commit.
  const bool written = write_all(file.get(), "probe\n") && ::fsync(file.get()) == 0;
  StoreResult<Done> result = Done{};
  if (!written) result = Unexpected{errno_error("write and fsync", path)};
  if (!file.close() && result) result = Unexpected{errno_error("close", path)};
  if (::unlink(path.c_str()) != 0 && result) result = Unexpected{errno_error("unlink", path)};
  if (!result) return result;
  return fsync_directory(dir);
}

StoreResult<std::string> read_file(const std::string& path) {
  FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.get() < 0) return Unexpected{errno_error("open", path)};
  std::string bytes;
  char buffer[8192];
  for (;;) {
    const ssize_t count = ::read(file.get(), buffer, sizeof buffer);
    if (count < 0) {
      if (errno == EINTR) continue;
      return Unexpected{errno_error("read", path)};
    }
    if (count == 0) break;
    bytes.append(buffer, static_cast<std::size_t>(count));
  }
  return bytes;
}

}  // namespace cdpr::store
