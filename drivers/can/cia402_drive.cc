#include "drivers/can/cia402_drive.h"

namespace cdpr::drivers::can {

using cia402::PowerState;

void Cia402Drive::reset() {
  has_status_ = false;
  power_state_ = PowerState::kNotReadyToSwitchOn;
  statusword_ = 0;
  setpoint_ = Setpoint::kIdle;
  queued_ = false;
  ack_seen_ = false;
  sent_any_ = false;
}

void Cia402Drive::set_goal(Goal goal) {
  goal_ = goal;
  fault_reset_allowed_ = goal == Goal::kEnabled;
  if (goal != Goal::kEnabled) {
    setpoint_ = Setpoint::kIdle;
    queued_ = false;
  }
}

void Cia402Drive::request_fault_reset() {
  if (goal_ == Goal::kNone || goal_ == Goal::kQuickStop) goal_ = Goal::kDisabled;
  fault_reset_allowed_ = true;
}

void Cia402Drive::on_status(const DriveTxPdo& pdo) {
  const PowerState before = power_state_;
  has_status_ = true;
  statusword_ = pdo.statusword;
  actual_counts_ = pdo.actual_counts;
  power_state_ = cia402::decode_power_state(pdo.statusword);
  if (power_state_ == PowerState::kOperationEnabled || (before == PowerState::kFault && power_state_ != before)) {
    fault_reset_allowed_ = false;  // used up: the next fault is latched
  }
  ack_seen_ = (pdo.statusword & cia402::kSwSetpointAcknowledge) != 0;
  if (power_state_ != PowerState::kOperationEnabled) {
    // Not enabled: hold wherever the drive is, so enabling never jumps.
    setpoint_ = Setpoint::kIdle;
    queued_ = false;
    target_counts_ = actual_counts_;
    return;
  }
  if (before != PowerState::kOperationEnabled) target_counts_ = actual_counts_;
  if (setpoint_ == Setpoint::kPending && ack_seen_) {
    setpoint_ = Setpoint::kAcknowledged;  // poll() now clears bit 4
  } else if (setpoint_ == Setpoint::kAcknowledged && !ack_seen_) {
    setpoint_ = Setpoint::kIdle;  // handshake finished
  }
  start_queued();
}

void Cia402Drive::start_queued() {
  if (!queued_ || setpoint_ != Setpoint::kIdle || ack_seen_) return;
  queued_ = false;
  target_counts_ = queued_target_counts_;
  setpoint_ = Setpoint::kPending;
}

void Cia402Drive::command_target(std::int32_t target_counts) {
  halt_ = false;
  queued_ = true;
  queued_target_counts_ = target_counts;
  start_queued();
}

hal::DriveState Cia402Drive::drive_state() const {
  if (!has_status_) return hal::DriveState::kUnknown;
  switch (power_state_) {
    case PowerState::kOperationEnabled: return hal::DriveState::kEnabled;
    case PowerState::kQuickStopActive: return hal::DriveState::kQuickStop;
    case PowerState::kFault:
    case PowerState::kFaultReactionActive: return hal::DriveState::kFault;
    default: return hal::DriveState::kDisabled;
  }
}

bool Cia402Drive::target_reached() const {
  return has_status_ && power_state_ == PowerState::kOperationEnabled && setpoint_ == Setpoint::kIdle && !queued_ &&
         (statusword_ & cia402::kSwTargetReached) != 0 && !ack_seen_;
}

std::uint16_t Cia402Drive::wanted_controlword(bool resend_due) const {
  switch (goal_) {
    case Goal::kNone:
      return last_controlword_;
    case Goal::kQuickStop:
      return cia402::kCwQuickStop;  // valid in every state that can move
    case Goal::kDisabled:
      if (power_state_ == PowerState::kFault && fault_reset_allowed_) break;  // the reset below
      return (power_state_ == PowerState::kQuickStopActive || power_state_ == PowerState::kFault)
                 ? cia402::kCwDisableVoltage
                 : cia402::kCwShutdown;
    case Goal::kEnabled:
      break;
  }
  switch (power_state_) {
    case PowerState::kNotReadyToSwitchOn:
    case PowerState::kFaultReactionActive:
      return cia402::kCwDisableVoltage;  // wait for the drive
    case PowerState::kFault:
      if (!fault_reset_allowed_) return cia402::kCwDisableVoltage;  // latched until enable() again
      // Rising edge of bit 7: when a reset did not take within the resend
      // interval, drop the bit once so the next frame is an edge again.
      return last_controlword_ == cia402::kCwFaultReset && resend_due ? cia402::kCwDisableVoltage
                                                                       : cia402::kCwFaultReset;
    case PowerState::kSwitchOnDisabled: return cia402::kCwShutdown;
    case PowerState::kReadyToSwitchOn: return cia402::kCwSwitchOn;
    case PowerState::kSwitchedOn: return cia402::kCwEnableOperation;
    case PowerState::kQuickStopActive: return cia402::kCwDisableVoltage;
    case PowerState::kOperationEnabled: break;
  }
  std::uint16_t cw = cia402::kCwEnableOperation | cia402::kCwChangeImmediately;
  if (halt_) cw |= cia402::kCwHalt;
  if (setpoint_ == Setpoint::kPending) cw |= cia402::kCwNewSetpoint;
  return cw;
}

bool Cia402Drive::settled() const {
  switch (goal_) {
    case Goal::kNone: return true;
    case Goal::kEnabled: return power_state_ == PowerState::kOperationEnabled && setpoint_ == Setpoint::kIdle && !queued_;
    case Goal::kDisabled:
      return power_state_ == PowerState::kReadyToSwitchOn || power_state_ == PowerState::kSwitchOnDisabled;
    case Goal::kQuickStop:
      return has_status_ && power_state_ != PowerState::kOperationEnabled &&
             power_state_ != PowerState::kSwitchedOn && power_state_ != PowerState::kReadyToSwitchOn;
  }
  return true;
}

std::optional<DriveRxPdo> Cia402Drive::poll(hal::TimeUs now_us) {
  if (goal_ == Goal::kNone) return std::nullopt;
  // Until the first statusword only a quick stop is worth sending blind.
  if (!has_status_ && goal_ != Goal::kQuickStop) return std::nullopt;
  const bool resend_due = !settled() && (!sent_any_ || now_us - last_sent_us_ >= resend_interval_us_);
  const std::uint16_t cw = wanted_controlword(resend_due);
  const bool changed = !sent_any_ || cw != last_controlword_ || target_counts_ != last_target_counts_;
  if (!changed && !resend_due) return std::nullopt;
  if (!changed) ++resends_;
  sent_any_ = true;
  last_controlword_ = cw;
  last_target_counts_ = target_counts_;
  last_sent_us_ = now_us;
  return DriveRxPdo{cw, target_counts_};
}

}  // namespace cdpr::drivers::can
