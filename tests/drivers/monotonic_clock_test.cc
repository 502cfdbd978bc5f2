#include "drivers/clock/monotonic_clock.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

namespace cdpr::drivers {
namespace {

TEST(MonotonicClock, AdvancesWithRealTimeAndNeverGoesBack) {
  // GIVEN the clock WHEN 20 ms of real time pass
  const MonotonicClock clock;
  const hal::TimeUs before_us = clock.now_us();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const hal::TimeUs after_us = clock.now_us();
  // THEN it advanced by at least 20 ms and not absurdly more
  EXPECT_GE(after_us - before_us, 20'000);
  EXPECT_LT(after_us - before_us, 2'000'000);
}

}  // namespace
}  // namespace cdpr::drivers
