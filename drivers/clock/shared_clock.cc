#include "drivers/clock/shared_clock.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <new>

#include "drivers/common/posix_status.h"

namespace cdpr::drivers {
namespace {

using Value = std::atomic<std::int64_t>;
static_assert(Value::is_always_lock_free, "a clock shared between processes needs a lock-free 64-bit atomic");

constexpr std::size_t kFileBytes = sizeof(Value);

// Maps the clock file: read-write for its writer, read-only for readers.
Value* map_clock(int fd, bool writable) {
  const int protection = writable ? PROT_READ | PROT_WRITE : PROT_READ;
  void* address = mmap(nullptr, kFileBytes, protection, MAP_SHARED, fd, 0);
  return address == MAP_FAILED ? nullptr : static_cast<Value*>(address);
}

}  // namespace

std::unique_ptr<SharedClock> SharedClock::create(const std::string& path, hal::TimeUs start_us, hal::Status& status) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    status = status_from_errno(errno, "clock " + path, "create");
    return nullptr;
  }
  Value* value = ftruncate(fd, kFileBytes) == 0 ? map_clock(fd, true) : nullptr;
  const int error = errno;
  ::close(fd);
  if (value == nullptr) {
    status = status_from_errno(error, "clock " + path, "map");
    return nullptr;
  }
  new (value) Value(start_us);
  status = hal::Status::Ok();
  return std::unique_ptr<SharedClock>(new SharedClock(value, true, true));
}

std::unique_ptr<SharedClock> SharedClock::open(const std::string& path, hal::Status& status) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    status = status_from_errno(errno, "clock " + path, "open");
    return nullptr;
  }
  const off_t size = lseek(fd, 0, SEEK_END);
  Value* value = size == static_cast<off_t>(kFileBytes) ? map_clock(fd, false) : nullptr;
  const int error = errno;
  ::close(fd);
  if (size != static_cast<off_t>(kFileBytes)) {
    status = hal::Status(hal::ErrorCode::kInvalidArgument,
                         "clock " + path + ": " + std::to_string(size) + " bytes, a clock file has " +
                             std::to_string(kFileBytes));
    return nullptr;
  }
  if (value == nullptr) {
    status = status_from_errno(error, "clock " + path, "map");
    return nullptr;
  }
  status = hal::Status::Ok();
  return std::unique_ptr<SharedClock>(new SharedClock(value, true, false));
}

std::unique_ptr<SharedClock> SharedClock::in_memory(hal::TimeUs start_us) {
  auto clock = std::unique_ptr<SharedClock>(new SharedClock(nullptr, false, true));
  clock->own_value_.store(start_us);
  clock->value_ = &clock->own_value_;
  return clock;
}

SharedClock::SharedClock(Value* value, bool mapped, bool writable)
    : value_(value), mapped_(mapped), writable_(writable) {}

SharedClock::~SharedClock() {
  if (mapped_) munmap(value_, kFileBytes);
}

hal::TimeUs SharedClock::now_us() const { return value_->load(std::memory_order_acquire); }

void SharedClock::advance_to(hal::TimeUs now_us) {
  if (!writable_) return;
  if (now_us > value_->load(std::memory_order_relaxed)) value_->store(now_us, std::memory_order_release);
}

}  // namespace cdpr::drivers
