#pragma once
// A hal::Button pressed by the test. press() is thread-safe; an injected
// error is returned once by the next take_presses().

#include <atomic>
#include <mutex>
#include <optional>

#include "hal/button.h"

namespace cdpr::fakes {

class FakeButton final : public hal::Button {
 public:
  void press() { presses_.fetch_add(1); }

  void fail_next(hal::Status error) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::move(error);
  }

  hal::Result<int> take_presses() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (error_) {
        hal::Status error = std::move(*error_);
        error_.reset();
        return error;
      }
    }
    return presses_.exchange(0);
  }

 private:
  std::atomic<int> presses_{0};
  std::mutex mutex_;
  std::optional<hal::Status> error_;
};

}  // namespace cdpr::fakes
