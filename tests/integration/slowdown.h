#pragma once
// The integration tests' time multiplier: 1 in the normal build, more in the
// sanitizer build (CDPR_TEST_SLOWDOWN from cmake/CdprTesting.cmake).
//
// Why it exists: these tests run the daemon against the virtual robot in
// wall-clock time. The robot's physics runs time_scale times faster than the
// wall clock, one step per pass of its loop; the daemon's fault timeouts
// (node silence, stale pose, load cell, settling), the drives' watch of the daemon's
// heartbeat (they quick-stop when it pauses longer) and the tests' deadlines
// are wall-clock times. Under ASan + UBSan every thread runs some times slower, so each
// physics step spans that much more simulated time (coarser motion between
// the daemon's commands, through which a cable's tension can dip below the
// run's limit) and a timeout fires on a thread that is merely slow. The sanitizer build runs
// the virtual robot slowdown() times slower and stretches the timeouts, the
// deadlines and the latency limits by as much, so a run sees the same
// simulated motion per step and the same margins as in the normal build.
// What each test checks is the same; in the normal build every figure is as
// written. CDPR_TEST_SLOWDOWN in the environment (a whole number >= 1)
// replaces the build's multiplier, to try another on a given machine.

#include <chrono>
#include <cstdlib>

#include "hal/clock.h"

namespace cdpr::integration {

inline int slowdown() {
  static const int multiplier = [] {
    const char* text = std::getenv("CDPR_TEST_SLOWDOWN");
    const int parsed = text != nullptr ? std::atoi(text) : 0;
    return parsed >= 1 ? parsed : CDPR_TEST_SLOWDOWN;
  }();
  return multiplier;
}

// A wall-clock duration of the normal build, in this build.
template <class Rep, class Period>
std::chrono::duration<Rep, Period> slowed(std::chrono::duration<Rep, Period> duration) {
  return duration * slowdown();
}
inline hal::TimeUs slowed_us(hal::TimeUs duration_us) { return duration_us * slowdown(); }
inline double slowed_ms(double duration_ms) { return duration_ms * slowdown(); }

// The virtual robot's time scale (simulated seconds per wall-clock second)
// in this build for `normal` in the normal build.
inline double robot_time_scale(double normal) { return normal / slowdown(); }

// The top-level line of a daemon configuration that acknowledges the
// timeouts the tests stretch beyond what a robot should run with (a
// virtual robot whose physics shares a thread with its nodes, on a loaded
// machine): docs/configuration.md, unsafe_ok.
inline constexpr const char* kLoadedMachineUnsafeOk =
    "unsafe_ok = [\"winches.heartbeat_timeout_ms\", \"winches.drive.consumer_heartbeat_ms\", "
    "\"load_cell.fault_timeout_ms\", \"limits.pose_stale_ms\"]\n";

}  // namespace cdpr::integration
