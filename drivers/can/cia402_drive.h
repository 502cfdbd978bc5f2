#pragma once
// Master-side state machine of one CiA 402 drive in profile position mode:
// walks the power state machine towards a goal (enabled, disabled, quick
// stop), runs the new-setpoint handshake for targets, and decides which
// RxPDO (controlword + target) to send and when to resend it.
//
// Explicit states, time passed in, no I/O: the winch bank feeds it received
// TxPDOs and sends what poll() returns. Resends after resend_interval_us
// when the drive has not moved on (lost frame, slow drive); the count of
// resends is kept for diagnostics. Real-time safe: no allocation.

#include <cstdint>
#include <optional>

#include "drivers/can/canopen.h"
#include "drivers/can/cia402.h"
#include "hal/clock.h"
#include "hal/winch_bank.h"

namespace cdpr::drivers::can {

class Cia402Drive {
 public:
  enum class Goal { kNone, kEnabled, kDisabled, kQuickStop };

  explicit Cia402Drive(hal::TimeUs resend_interval_us) : resend_interval_us_(resend_interval_us) {}

  // Forgets everything heard (node rebooted or lost); keeps the goal.
  void reset();
  // kEnabled allows one fault reset (the operator's explicit request); a
  // fault after the drive was enabled stays latched until the next call.
  void set_goal(Goal goal);
  Goal goal() const { return goal_; }
  // The operator's request: a drive in fault gets one fault reset (and
  // stays disabled) whatever the goal.
  void request_fault_reset();
  // Halt bit (decelerate and hold) while enabled; a new target clears it.
  void set_halt(bool halt) { halt_ = halt; }

  // A TxPDO from the drive.
  void on_status(const DriveTxPdo& pdo);
  // Starts the new-setpoint handshake for `target_counts`. Precondition:
  // drive_state() == kEnabled (checked by the caller). The CiA 402
  // handshake is finished before a new one starts: bit 4 up, acknowledge
  // seen 1, bit 4 down, acknowledge seen 0. A target given meanwhile waits
  // (the latest one wins), so a late acknowledgement of the previous
  // set-point is never taken for the new one and no edge falls on a drive
  // that still refuses set-points.
  void command_target(std::int32_t target_counts);

  // The RxPDO to send now, if any: when the wanted controlword or target
  // changed, or as a resend when the drive has not moved on for
  // resend_interval_us.
  std::optional<DriveRxPdo> poll(hal::TimeUs now_us);

  bool has_status() const { return has_status_; }
  cia402::PowerState power_state() const { return power_state_; }
  hal::DriveState drive_state() const;
  std::int32_t actual_counts() const { return actual_counts_; }
  std::int32_t target_counts() const { return target_counts_; }
  // Latest target acknowledged by the drive and reported reached.
  bool target_reached() const;
  std::uint64_t resends() const { return resends_; }

 private:
  // kPending: bit 4 high, waiting for the acknowledge; kAcknowledged: bit 4
  // low, waiting for the acknowledge to clear.
  enum class Setpoint { kIdle, kPending, kAcknowledged };
  void start_queued();

  // The controlword that moves the drive towards the goal from its state.
  std::uint16_t wanted_controlword(bool resend_due) const;
  // The drive is where the goal wants it (nothing to resend).
  bool settled() const;

  hal::TimeUs resend_interval_us_;
  Goal goal_ = Goal::kNone;
  bool halt_ = false;
  bool has_status_ = false;
  cia402::PowerState power_state_ = cia402::PowerState::kNotReadyToSwitchOn;
  std::uint16_t statusword_ = 0;
  std::int32_t actual_counts_ = 0;
  std::int32_t target_counts_ = 0;
  Setpoint setpoint_ = Setpoint::kIdle;
  bool queued_ = false;
  std::int32_t queued_target_counts_ = 0;
  bool ack_seen_ = false;  // the acknowledge bit of the latest statusword
  bool sent_any_ = false;
  std::uint16_t last_controlword_ = 0;
  std::int32_t last_target_counts_ = 0;
  hal::TimeUs last_sent_us_ = 0;
  std::uint64_t resends_ = 0;
  bool fault_reset_allowed_ = false;
};

}  // namespace cdpr::drivers::can
