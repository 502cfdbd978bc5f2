#pragma once
// A behavioural hal::LoadCell: reports the tension the test (or a physics
// callback) sets, stamped with the injected clock, and can fail like the real
// bus: a number of failing reads (timeouts, CRC errors) or failing for good.

#include <cmath>
#include <deque>
#include <functional>
#include <tuple>
#include <utility>

#include "hal/clock.h"
#include "hal/load_cell.h"

namespace cdpr::fakes {

class FakeLoadCell final : public hal::LoadCell {
 public:
  explicit FakeLoadCell(const hal::Clock& clock) : clock_(clock) {}

  // The tension and stable flag the next reads report.
  void set_tension(double tension_n, bool stable = true) {
    tension_n_ = tension_n;
    stable_ = stable;
  }
  // When set, called at every read for the tension [N] and stable flag
  // (e.g. from the fake winches' state); overrides set_tension().
  void set_source(std::function<std::pair<double, bool>(hal::TimeUs now_us)> source) {
    source_ = std::move(source);
  }
  // The next `count` reads fail with `error` (queued after earlier ones).
  void fail_next(const hal::Status& error, int count = 1) {
    for (int i = 0; i < count; ++i) queued_errors_.push_back(error);
  }
  // Every read fails with `error` until cleared with hal::Status::Ok().
  void fail_always(hal::Status error) { permanent_error_ = std::move(error); }
  void fail_open(hal::Status error) { open_error_ = std::move(error); }

  bool is_open() const { return open_; }
  int reads() const { return reads_; }

  hal::Status open() override {
    if (!open_error_.ok()) return open_error_;
    open_ = true;
    return hal::Status::Ok();
  }
  void close() override { open_ = false; }

  hal::Result<hal::TensionSample> read() override {
    ++reads_;
    if (!open_) return hal::Status(hal::ErrorCode::kInvalidState, "fake load cell: not open");
    if (!permanent_error_.ok()) return permanent_error_;
    if (!queued_errors_.empty()) {
      hal::Status error = queued_errors_.front();
      queued_errors_.pop_front();
      return error;
    }
    const hal::TimeUs now_us = clock_.now_us();
    double tension_n = tension_n_;
    bool stable = stable_;
    if (source_) std::tie(tension_n, stable) = source_(now_us);
    if (!std::isfinite(tension_n)) {
      return hal::Status(hal::ErrorCode::kDeviceFault, "fake load cell: non-finite tension");
    }
    return hal::TensionSample{tension_n, stable, now_us};
  }

 private:
  const hal::Clock& clock_;
  double tension_n_ = 0.0;
  bool stable_ = true;
  std::function<std::pair<double, bool>(hal::TimeUs)> source_;
  std::deque<hal::Status> queued_errors_;
  hal::Status permanent_error_;
  hal::Status open_error_;
  bool open_ = false;
  int reads_ = 0;
};

}  // namespace cdpr::fakes
