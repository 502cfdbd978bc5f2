#pragma once
// Monotonic time for the daemon and its drivers, injected so that logic never
// reads the wall clock: production uses a CLOCK_MONOTONIC implementation in
// drivers/, tests a manual clock they advance by hand (tests/fakes/).
//
// Units: microseconds since an arbitrary epoch (boot, or 0 in tests); only
// differences mean anything. Never goes backwards.
// Thread and real-time safety: now_us() must be callable from any thread, must
// not block or allocate.

#include <cstdint>

namespace cdpr::hal {

using TimeUs = std::int64_t;  // monotonic time or duration [us]

class Clock {
 public:
  virtual ~Clock() = default;
  virtual TimeUs now_us() const = 0;
};

}  // namespace cdpr::hal
