#pragma once
// The production hal::Clock: CLOCK_MONOTONIC in microseconds (time since
// boot, never jumps with NTP or the operator setting the date). Thread-safe,
// real-time safe (a vDSO call, no allocation).

#include "hal/clock.h"

namespace cdpr::drivers {

class MonotonicClock final : public hal::Clock {
 public:
  hal::TimeUs now_us() const override;
};

}  // namespace cdpr::drivers
