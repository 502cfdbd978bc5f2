#include "drivers/clock/monotonic_clock.h"

#include <time.h>

namespace cdpr::drivers {

hal::TimeUs MonotonicClock::now_us() const {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<hal::TimeUs>(now.tv_sec) * 1'000'000 + now.tv_nsec / 1000;
}

}  // namespace cdpr::drivers
