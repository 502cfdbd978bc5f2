#pragma once
// A behavioural hal::WinchBank: each enabled winch moves its payout towards
// its target at a fixed speed as the injected time passes between update()
// calls; commands take effect at the next update(), like the real drives.
// Faults are injected per winch: a silent node (heartbeat stops, the winch is
// dead after the heartbeat timeout), a drive fault, failing sends. The drives
// may watch the master's heartbeat, which the real bank sends from update():
// a longer pause between two update() calls quick-stops them.
// Observers (moving(), all_stopped(), quick_stops()) let tests check the end
// state ("winches stopped") rather than a recorded call sequence.

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "hal/winch_bank.h"

namespace cdpr::fakes {

class FakeWinchBank final : public hal::WinchBank {
 public:
  struct Options {
    int winch_count = 4;
    double speed_m_per_s = 0.5;            // profile speed of every winch
    double reached_tolerance_m = 1e-4;     // target reached within this
    hal::TimeUs heartbeat_timeout_us = 300'000;
    // The drives' consumer heartbeat time (0x1016 with abort connection
    // option 3: quick stop); 0: not watched.
    hal::TimeUs consumer_heartbeat_us = 0;
  };

  FakeWinchBank() : FakeWinchBank(Options{}) {}
  explicit FakeWinchBank(const Options& options) : options_(options), winches_(options.winch_count) {}

  // ---- test controls ----
  // Sets a winch's payout (and target) directly, e.g. the start pose.
  void set_payout(int winch, double payout_m) {
    at(winch).payout_m = payout_m;
    at(winch).target_m = payout_m;
  }
  // The node stops sending heartbeats and positions from now on (or again).
  void silence(int winch, bool silent = true) { at(winch).silent = silent; }
  // The drive goes to fault at the next update() and stops.
  void inject_fault(int winch) { at(winch).inject_fault = true; }
  // The operator's reset: a drive in fault goes to disabled.
  hal::Status reset_faults() override {
    if (hal::Status s = check_command(); !s.ok()) return s;
    for (Winch& w : winches_) {
      if (w.state == hal::DriveState::kFault) w.state = hal::DriveState::kDisabled;
    }
    ++fault_resets_;
    return hal::Status::Ok();
  }
  int fault_resets() const { return fault_resets_; }
  // Every command and update() fails with `error` until cleared with Ok().
  void fail_io(hal::Status error) { io_error_ = std::move(error); }

  bool is_open() const { return open_; }
  // True when the winch's payout changed during the last update().
  bool moving(int winch) const { return at(winch).moved; }
  // No winch moves now, and none can move without a new command: each is
  // disabled, quick-stopped, faulted, halted, or at its target.
  bool all_stopped() const {
    return std::all_of(winches_.begin(), winches_.end(), [&](const Winch& w) {
      return w.state != hal::DriveState::kEnabled || w.halted ||
             std::abs(w.target_m - w.payout_m) <= options_.reached_tolerance_m;
    });
  }
  int quick_stops() const { return quick_stops_; }
  int enables() const { return enables_; }  // enable() commands accepted
  int halts() const { return halts_; }
  int updates() const { return updates_; }
  // Times the drives quick-stopped because update() paused too long.
  int heartbeat_losses() const { return heartbeat_losses_; }

  // ---- hal::WinchBank ----
  int winch_count() const override { return options_.winch_count; }

  hal::Status open() override {
    if (!io_error_.ok()) return io_error_;
    open_ = true;
    return hal::Status::Ok();
  }
  void close() override { open_ = false; }

  hal::Status update(hal::TimeUs now_us) override {
    if (!open_) return not_open();
    if (!io_error_.ok()) return io_error_;
    const double dt_s = last_update_us_ < 0 ? 0.0 : 1e-6 * static_cast<double>(now_us - last_update_us_);
    ++updates_;
    if (options_.consumer_heartbeat_us > 0 && last_update_us_ >= 0 &&
        now_us - last_update_us_ > options_.consumer_heartbeat_us) {
      ++heartbeat_losses_;
      for (Winch& w : winches_) {
        if (w.state == hal::DriveState::kEnabled) w.state = hal::DriveState::kQuickStop;
        w.target_m = w.payout_m;
      }
    }
    last_update_us_ = now_us;
    now_us_ = now_us;
    for (Winch& w : winches_) step(w, dt_s, now_us);
    return hal::Status::Ok();
  }

  hal::WinchStatus status(int winch) const override {
    const Winch& w = at(winch);
    hal::WinchStatus s;
    s.payout_m = w.reported_payout_m;
    s.position_valid = w.last_heard_us >= 0;
    s.position_time_us = w.last_heard_us;
    s.target_payout_m = w.target_m;
    s.heartbeat_age_us = w.last_heard_us < 0 ? -1 : now_us_ - w.last_heard_us;
    s.alive = w.last_heard_us >= 0 && s.heartbeat_age_us <= options_.heartbeat_timeout_us;
    s.drive = w.state;
    s.target_reached = w.target_reached;
    return s;
  }

  hal::WinchBankCounters counters() const override { return counters_; }

  hal::Status enable() override {
    if (hal::Status s = check_command(); !s.ok()) return s;
    for (Winch& w : winches_) w.request = Request::kEnable;
    ++enables_;
    return hal::Status::Ok();
  }
  hal::Status disable() override {
    if (hal::Status s = check_command(); !s.ok()) return s;
    for (Winch& w : winches_) w.request = Request::kDisable;
    return hal::Status::Ok();
  }
  hal::Status set_target_payout(int winch, double payout_m) override {
    if (winch < 0 || winch >= winch_count() || !std::isfinite(payout_m)) {
      return hal::Status(hal::ErrorCode::kInvalidArgument, "fake winch: bad index or target");
    }
    if (hal::Status s = check_command(); !s.ok()) return s;
    Winch& w = winches_[winch];
    if (w.state != hal::DriveState::kEnabled || !status(winch).alive) {
      return hal::Status(hal::ErrorCode::kInvalidState, "fake winch " + std::to_string(winch) +
                                                            ": drive not enabled or node dead");
    }
    w.target_m = payout_m;
    w.halted = false;
    w.target_reached = false;  // until the drive has seen it (next update)
    ++counters_.frames_tx;
    return hal::Status::Ok();
  }
  hal::Status halt() override {
    if (hal::Status s = check_command(); !s.ok()) return s;
    ++halts_;
    for (Winch& w : winches_) w.halted = true;
    return hal::Status::Ok();
  }
  hal::Status quick_stop() override {
    ++quick_stops_;
    if (!open_) return not_open();
    if (!io_error_.ok()) return io_error_;
    // A real quick stop brakes hard; the fake stops at once (and for good,
    // even before the next update(): what a safety check wants to see).
    for (Winch& w : winches_) {
      if (w.state == hal::DriveState::kEnabled) w.state = hal::DriveState::kQuickStop;
      w.target_m = w.payout_m;
      w.request = Request::kNone;
    }
    return hal::Status::Ok();
  }
  bool motion_finished() const override {
    for (int i = 0; i < winch_count(); ++i) {
      const hal::WinchStatus s = status(i);
      if (!s.alive || s.drive != hal::DriveState::kEnabled || !s.target_reached) return false;
    }
    return true;
  }

 private:
  enum class Request { kNone, kEnable, kDisable };
  struct Winch {
    double payout_m = 0.0;           // true payout
    double reported_payout_m = 0.0;  // frozen while silent
    double target_m = 0.0;
    hal::DriveState state = hal::DriveState::kDisabled;
    Request request = Request::kNone;
    bool halted = false;
    bool silent = false;
    bool inject_fault = false;
    bool target_reached = true;
    bool moved = false;
    hal::TimeUs last_heard_us = -1;
  };
  int fault_resets_ = 0;
  int updates_ = 0;
  int heartbeat_losses_ = 0;

  Winch& at(int winch) {
    if (winch < 0 || winch >= options_.winch_count) std::abort();  // as the real bank: broken invariant
    return winches_[static_cast<std::size_t>(winch)];
  }
  const Winch& at(int winch) const {
    if (winch < 0 || winch >= options_.winch_count) std::abort();
    return winches_[static_cast<std::size_t>(winch)];
  }
  hal::Status not_open() const { return hal::Status(hal::ErrorCode::kInvalidState, "fake winch bank: not open"); }
  hal::Status check_command() {
    if (!open_) return not_open();
    if (!io_error_.ok()) {
      ++counters_.errors;
      return io_error_;
    }
    return hal::Status::Ok();
  }

  void step(Winch& w, double dt_s, hal::TimeUs now_us) {
    const double before_m = w.payout_m;
    if (w.inject_fault) {
      w.inject_fault = false;
      w.state = hal::DriveState::kFault;
    }
    // A silent node also ignores commands: its bus connection is gone.
    if (!w.silent) {
      switch (w.request) {
        case Request::kEnable:
          w.state = hal::DriveState::kEnabled;
          w.target_m = w.payout_m;  // hold where it stands
          w.halted = false;
          break;
        case Request::kDisable: w.state = hal::DriveState::kDisabled; break;
        case Request::kNone: break;
      }
      w.request = Request::kNone;
    }
    if (w.state == hal::DriveState::kEnabled && !w.halted) {
      const double step_m = options_.speed_m_per_s * dt_s;
      const double error_m = w.target_m - w.payout_m;
      w.payout_m += std::clamp(error_m, -step_m, step_m);
    }
    w.moved = w.payout_m != before_m;
    w.target_reached = std::abs(w.target_m - w.payout_m) <= options_.reached_tolerance_m;
    if (!w.silent) {
      w.last_heard_us = now_us;
      w.reported_payout_m = w.payout_m;
      ++counters_.frames_rx;
    }
  }

  Options options_;
  std::vector<Winch> winches_;
  hal::Status io_error_;
  bool open_ = false;
  hal::TimeUs last_update_us_ = -1;
  hal::TimeUs now_us_ = 0;
  int quick_stops_ = 0;
  int enables_ = 0;
  int halts_ = 0;
  hal::WinchBankCounters counters_;
};

}  // namespace cdpr::fakes
