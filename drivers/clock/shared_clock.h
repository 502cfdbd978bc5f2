#pragma once
// A hal::Clock kept in a small shared file that one process advances and
// others read: the clock of a simulator, so that a daemon run against it
// counts its timeouts in the simulated robot's time, as ROS nodes do with
// use_sim_time. A simulator starved of CPU is then a slower robot to the
// daemon, never a silent node, a stale pose or a settling timeout.
//
// The file holds one lock-free 64-bit atomic: microseconds on the writer's
// clock, which only the writer moves, never backwards. create() makes (or
// truncates) it for the writer; open() maps it read-only for a reader, which
// sees every advance at once (MAP_SHARED, same machine).
//
// Thread and real-time safety: now_us() and advance_to() are one atomic
// load or store: callable from any thread, never block, never allocate.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "hal/clock.h"
#include "hal/status.h"

namespace cdpr::drivers {

class SharedClock final : public hal::Clock {
 public:
  // The writer's clock at `path`, starting at `start_us`.
  static std::unique_ptr<SharedClock> create(const std::string& path, hal::TimeUs start_us, hal::Status& status);
  // A reader of the clock another process created at `path`.
  static std::unique_ptr<SharedClock> open(const std::string& path, hal::Status& status);
  // An unshared clock in this process's memory (a simulator run in-process).
  static std::unique_ptr<SharedClock> in_memory(hal::TimeUs start_us);
  ~SharedClock() override;
  SharedClock(const SharedClock&) = delete;
  SharedClock& operator=(const SharedClock&) = delete;

  hal::TimeUs now_us() const override;
  // Moves the clock on to `now_us` (the writer only; an earlier time is ignored).
  void advance_to(hal::TimeUs now_us);

 private:
  SharedClock(std::atomic<std::int64_t>* value, bool mapped, bool writable);

  std::atomic<std::int64_t>* value_;
  std::atomic<std::int64_t> own_value_{0};  // in_memory()
  bool mapped_;
  bool writable_;
};

}  // namespace cdpr::drivers
