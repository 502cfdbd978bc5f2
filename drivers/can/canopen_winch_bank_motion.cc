// The winch bank's drive commands: enabling, stopping, single-winch targets
// and coordinated moves whose profile velocities make every winch arrive
// together. Bus supervision and status live in canopen_winch_bank.cc.
#include "drivers/can/canopen_winch_bank.h"
#include "drivers/can/move_profile.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace cdpr::drivers::can {

hal::Status CanopenWinchBank::stop_all(Cia402Drive::Goal goal) {
  if (hal::Status s = check_open(); !s.ok()) return s;
  cancel_coordinated_move();
  for (Winch& w : winches_) {
    w.enable = EnableStep::kNone;
    w.drive.set_goal(goal);
  }
  return poll_drives(now_us_);
}

hal::Status CanopenWinchBank::enable() {
  if (hal::Status s = check_open(); !s.ok()) return s;
  // The goal is set once the drive's mode is written and checked (update()).
  for (Winch& w : winches_) {
    if (!w.fault.empty()) continue;
    if (w.drive_node.configurator.state() == NodeConfigurator::State::kRunning && w.enable == EnableStep::kCheckMode) {
      continue;  // a check already under way
    }
    w.enable = EnableStep::kCheckMode;
    w.mode_check_started = false;
  }
  return hal::Status::Ok();
}

hal::Status CanopenWinchBank::reset_faults() {
  if (hal::Status s = check_open(); !s.ok()) return s;
  for (Winch& w : winches_) {
    w.fault.clear();
    w.emergency.clear();
    w.encoder.reset();  // the next reading starts afresh
    w.encoder_time_us = -1;
    w.drive.request_fault_reset();
    for (Node* node : {&w.drive_node, &w.encoder_node}) {
      if (node->id == 0 || node->configured) continue;
      node->configurator.cancel();
      node->configure_at_us = now_us_;  // a refused configuration is tried again
    }
  }
  return poll_drives(now_us_);
}

hal::Status CanopenWinchBank::disable() { return stop_all(Cia402Drive::Goal::kDisabled); }
hal::Status CanopenWinchBank::quick_stop() { return stop_all(Cia402Drive::Goal::kQuickStop); }

void CanopenWinchBank::cancel_coordinated_move() {
  coordinated_move_pending_ = false;
  for (Winch& w : winches_) {
    if (w.profile_pending) w.drive_node.configurator.cancel();
    w.profile_pending = false;
  }
}

hal::Status CanopenWinchBank::halt() {
  if (hal::Status s = check_open(); !s.ok()) return s;
  cancel_coordinated_move();
  for (Winch& w : winches_) w.drive.set_halt(true);
  return poll_drives(now_us_);
}

hal::Result<std::int32_t> CanopenWinchBank::target_counts(int winch, double payout_target_m) {
  if (winch < 0 || winch >= winch_count() || !std::isfinite(payout_target_m)) {
    return hal::Status(hal::ErrorCode::kInvalidArgument,
                       "CAN winch bank: bad winch index " + std::to_string(winch) + " or non-finite target");
  }
  if (hal::Status s = check_open(); !s.ok()) return s;
  Winch& w = winches_[static_cast<std::size_t>(winch)];
  const hal::WinchStatus now = status(winch);
  if (!now.alive || now.drive != hal::DriveState::kEnabled || !now.position_valid || now.fault) {
    return hal::Status(hal::ErrorCode::kInvalidState,
                       "winch " + std::to_string(winch) + " (node " + std::to_string(w.drive_node.id) + "): " +
                           (now.alive ? std::string("drive ") + hal::to_string(now.drive) : std::string("node dead")) +
                           (now.fault ? " with a fault" : "") + ", target refused");
  }
  if (std::abs(payout_target_m - now.payout_m) > config_.max_move_m) {
    return hal::Status(hal::ErrorCode::kInvalidArgument,
                       "winch " + std::to_string(winch) + ": a move of " + std::to_string(payout_target_m - now.payout_m) +
                           " m exceeds max_move " + std::to_string(config_.max_move_m) + " m, target refused");
  }
  const double m_per_count = config_.winches[static_cast<std::size_t>(winch)].drive_m_per_count;
  const double target = static_cast<double>(w.drive.actual_counts()) +
                        std::round((payout_target_m - now.payout_m) / m_per_count);
  if (target < std::numeric_limits<std::int32_t>::min() || target > std::numeric_limits<std::int32_t>::max()) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "winch " + std::to_string(winch) + ": target out of drive range");
  }
  return static_cast<std::int32_t>(target);
}

hal::Status CanopenWinchBank::set_target_payout(int winch, double payout_target_m) {
  hal::Result<std::int32_t> target = target_counts(winch, payout_target_m);
  if (!target.ok()) return target.status();
  Winch& w = winches_[static_cast<std::size_t>(winch)];
  w.target_payout_m = payout_target_m;
  w.drive.command_target(target.value());
  return poll_drives(now_us_);
}

hal::Status CanopenWinchBank::set_target_payouts(const double* payouts_m) {
  // Everything checked before anything is sent: a refused winch moves none.
  double longest_m = 0.0;
  for (int i = 0; i < winch_count(); ++i) {
    hal::Result<std::int32_t> target = target_counts(i, payouts_m[i]);
    if (!target.ok()) return target.status();
    Winch& w = winches_[static_cast<std::size_t>(i)];
    w.pending_target_counts = target.value();
    longest_m = std::max(longest_m, std::abs(payouts_m[i] - status(i).payout_m));
  }
  for (int i = 0; i < winch_count(); ++i) {
    Winch& w = winches_[static_cast<std::size_t>(i)];
    const double share = longest_m > 0.0 ? std::abs(payouts_m[i] - status(i).payout_m) / longest_m : 1.0;
    // In the drive's own units (drive_units.h), 0x6085 with the others (move_profile.h).
    const MoveProfileCounts p = scaled_move_profile(config_.drive, share, w.units);
    w.profile_steps[0].value = p.velocity;
    w.profile_steps[1].value = p.acceleration;
    w.profile_steps[2].value = p.deceleration;
    w.profile_steps[3].value = p.quick_stop_deceleration;
    w.profile_pending = true;
    w.drive_node.configurator.start(&w.profile_steps);
    w.target_payout_m = payouts_m[i];
  }
  coordinated_move_pending_ = true;
  return service_coordinated_move(now_us_);
}

hal::Status CanopenWinchBank::service_coordinated_move(hal::TimeUs now_us) {
  if (!coordinated_move_pending_) return hal::Status::Ok();
  hal::Status first_error;
  bool all_written = true;
  for (Winch& w : winches_) {
    if (!w.profile_pending) continue;
    NodeConfigurator& c = w.drive_node.configurator;
    std::optional<CanFrame> frame = c.poll(now_us);
    if (frame) {
      if (hal::Status s = send(*frame); !s.ok() && first_error.ok()) first_error = s;
    }
    if (c.state() == NodeConfigurator::State::kDone) {
      w.profile_pending = false;
    } else if (c.state() == NodeConfigurator::State::kFailed || c.state() == NodeConfigurator::State::kNoAnswer) {
      if (w.fault.empty()) w.fault = "move profile refused, no winch moved: " + c.error();
      w.profile_pending = false;
    } else {
      all_written = false;
    }
  }
  if (!all_written) return first_error;
  coordinated_move_pending_ = false;
  // A winch whose profile was refused (or that faulted meanwhile) would
  // leave the others pulling the platform off the line alone: none moves.
  // The refusal is that winch's latched fault (status().fault).
  const bool refused = std::any_of(winches_.begin(), winches_.end(), [](const Winch& w) { return !w.fault.empty(); });
  if (!refused) {
    // Every profile is in place: the targets go out in this one cycle.
    for (Winch& w : winches_) w.drive.command_target(w.pending_target_counts);
  }
  if (hal::Status s = poll_drives(now_us); !s.ok() && first_error.ok()) first_error = s;
  return first_error;
}

std::string CanopenWinchBank::fault_text(int winch) const {
  if (winch < 0 || winch >= winch_count()) std::abort();  // caller's broken invariant (hal/winch_bank.h)
  const Winch& w = winches_[static_cast<std::size_t>(winch)];
  std::string text = w.fault;
  if (!w.error_code.empty()) text += (text.empty() ? "" : "; ") + w.error_code;
  if (!w.emergency.empty()) text += (text.empty() ? "" : "; last ") + w.emergency;
  return text;
}

bool CanopenWinchBank::motion_finished() const {
  if (coordinated_move_pending_) return false;
  for (int i = 0; i < winch_count(); ++i) {
    const hal::WinchStatus s = status(i);
    if (!s.alive || s.drive != hal::DriveState::kEnabled || !s.target_reached) return false;
  }
  return true;
}

}  // namespace cdpr::drivers::can
