#pragma once
// A hal::Button pressed in-process: the daemon's control socket calls press()
// when calibctl sends "start". press() may be called from any thread; the
// daemon loop takes the presses. Lock-free, never blocks, never fails.

#include <atomic>

#include "hal/button.h"

namespace cdpr::drivers::button {

class CommandButton final : public hal::Button {
 public:
  void press() { presses_.fetch_add(1, std::memory_order_relaxed); }
  hal::Result<int> take_presses() override { return presses_.exchange(0, std::memory_order_relaxed); }

 private:
  std::atomic<int> presses_{0};
};

}  // namespace cdpr::drivers::button
