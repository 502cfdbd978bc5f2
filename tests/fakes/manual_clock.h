#pragma once
// A hal::Clock that moves only when a test says so, so timing tests are exact
// and take no wall time. Thread-safe (atomic), never goes backwards.

#include <atomic>
#include <cassert>

#include "hal/clock.h"

namespace cdpr::fakes {

class ManualClock final : public hal::Clock {
 public:
  explicit ManualClock(hal::TimeUs start_us = 0) : now_us_(start_us) {}

  hal::TimeUs now_us() const override { return now_us_.load(); }

  void advance_us(hal::TimeUs delta_us) {
    assert(delta_us >= 0);
    now_us_ += delta_us;
  }
  void advance_ms(hal::TimeUs delta_ms) { advance_us(delta_ms * 1000); }
  void set_us(hal::TimeUs now_us) {
    assert(now_us >= now_us_.load());
    now_us_ = now_us;
  }

 private:
  std::atomic<hal::TimeUs> now_us_;
};

}  // namespace cdpr::fakes
