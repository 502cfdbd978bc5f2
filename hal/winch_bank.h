#pragma once
// The robot's winches: one encoder (cable payout) and one position drive per
// cable, commanded together. On the real robot: CANopen, CiA 406 encoders and
// CiA 402 drives (drivers/can); in tests: a behavioural fake (tests/fakes).
//
// Lifecycle (as ros2_control's system_interface: configure, activate, cyclic
// read/write, deactivate):
//   construct (configuration only, no I/O)
//   -> open()                       connect the bus, start the nodes
//   -> enable()                     request "operation enabled" on every drive
//   -> update(now) cyclically       process input, advance state machines
//      set_target_payout(), halt(), quick_stop() as needed
//   -> disable() -> close()
// Commands are requests: their effect shows in status() after later update()
// calls (e.g. enable() takes several statusword round trips). A command's
// Status only says whether it could be sent.
//
// Units: payout [m] of cable paid out from the winch as the encoder counts it
// (relative: zero wherever the encoder's zero is; the calibration estimates
// the offsets, docs/DESIGN.md). Larger payout = longer free cable.
// Time: TimeUs of the injected hal::Clock, microseconds, monotonic.
// Thread safety: one thread at a time per instance (the daemon loop).
// Real-time safety: update(), status(), motion_finished() and the motion
// commands never block (sends are non-blocking; a full transmit queue is an
// error) and do not allocate when ok. open() may block for the connect.

#include <cstdint>
#include <string>

#include "hal/clock.h"
#include "hal/status.h"

namespace cdpr::hal {

// State of one drive, after the CiA 402 power state machine (simplified).
enum class DriveState {
  kUnknown,            // no statusword seen yet
  kDisabled,           // not ready / switch on disabled / ready to switch on / switched on
  kEnabled,            // operation enabled: accepts targets
  kQuickStop,          // quick stop active: braking or stopped, rejects targets
  kFault,              // fault or fault reaction active
};

constexpr const char* to_string(DriveState state) {
  switch (state) {
    case DriveState::kUnknown: return "unknown";
    case DriveState::kDisabled: return "disabled";
    case DriveState::kEnabled: return "enabled";
    case DriveState::kQuickStop: return "quick stop";
    case DriveState::kFault: return "fault";
  }
  return "unknown";
}

struct WinchStatus {
  double payout_m = 0.0;          // last encoder position [m]; meaningful if position_valid
  bool position_valid = false;    // at least one encoder reading received
  TimeUs position_time_us = 0;    // local time of that reading [us]
  double target_payout_m = 0.0;   // last commanded target [m]
  bool alive = false;             // every node of this winch heard within its heartbeat timeout
  TimeUs heartbeat_age_us = -1;   // now - oldest last heartbeat of its nodes [us]; -1: never heard
  DriveState drive = DriveState::kUnknown;
  bool target_reached = false;    // drive reports the latest target reached (and acknowledged)
  bool fault = false;             // a fault latched by the bank (fault_text() says which)
};

// One bus node of a winch (its drive or its encoder) as the bank last heard
// it, for the operator (calibctl status); nothing in the run decides on it.
// The texts are static strings (no allocation); ages are now - last [us],
// -1 when never heard.
struct NodeStatus {
  const char* role = "";             // "drive" or "encoder"
  int node_id = 0;
  const char* nmt = "unknown";       // NMT state of its heartbeat: "boot-up", "pre-operational",
                                     // "operational", "stopped"; "silent" past the heartbeat timeout
  bool configured = false;           // the master's configuration taken and verified
  const char* power_state = "";      // drives: CiA 402 state ("operation enabled", "quick stop
                                     // active", "fault", ...); "" for encoders or before a statusword
  std::uint16_t error_code = 0;      // drives in fault: 0x603F as read (0: not read or none)
  const char* error_text = "";       // its meaning
  std::uint16_t emcy_code = 0;       // the last EMCY from this node (0: none since open)
  std::uint8_t emcy_register = 0;    // its error register
  const char* emcy_text = "";
  TimeUs pdo_age_us = -1;            // since its last TPDO
  TimeUs heartbeat_age_us = -1;      // since its last heartbeat
};

// Bus counters for diagnostics (PX4-style perf counters, no log per frame).
struct WinchBankCounters {
  std::uint64_t frames_rx = 0;
  std::uint64_t frames_tx = 0;
  std::uint64_t frames_ignored = 0;  // well-formed frames for nobody we know
  std::uint64_t errors = 0;          // transport errors, malformed frames, failed sends
};

class WinchBank {
 public:
  virtual ~WinchBank() = default;

  // Number of winches, fixed at construction (4 on the robots of docs/DESIGN.md).
  virtual int winch_count() const = 0;

  // Connects the bus and starts the nodes (CANopen NMT start). Errors:
  // kNotConnected, kIoError, kInvalidArgument (bad configuration).
  virtual Status open() = 0;
  // Stops sending and releases the bus; safe to call twice or without open().
  // Does NOT stop the drives: call quick_stop() or disable() first.
  virtual void close() = 0;

  // Reads all pending input without blocking, updates status(), runs the
  // per-node state machines and timeouts (heartbeat, enable sequence).
  // Errors: kNotConnected (bus lost), kIoError; a dead node or a drive fault
  // is not an error of update() but shows in status() (alive, drive).
  virtual Status update(TimeUs now_us) = 0;

  // Snapshot of one winch, 0 <= winch < winch_count() (checked: a bad index
  // is a broken invariant of the caller).
  virtual WinchStatus status(int winch) const = 0;
  virtual WinchBankCounters counters() const = 0;
  // What the latched fault of one winch is (node, object, values), empty
  // when none. Allocates: for messages, not for the cyclic path.
  virtual std::string fault_text(int winch) const {
    (void)winch;
    return {};
  }

  // The bus nodes of one winch (0 <= node < node_count(winch)), for the
  // operator's status. Banks without nodes (fakes) have none.
  virtual int node_count(int winch) const {
    (void)winch;
    return 0;
  }
  virtual NodeStatus node_status(int winch, int node) const {
    (void)winch;
    (void)node;
    return {};
  }

  // The operator's explicit request to clear latched faults (the bank's own,
  // e.g. a refused configuration, which is then tried again, or an encoder
  // jump; and a drive's CiA 402 fault, reset once). Nothing resets a fault
  // without it but enable() at the start of a run.
  virtual Status reset_faults() { return Status::Ok(); }

  // Requests operation enabled on every drive (resets a fault first). Holds
  // the current position: the target is set to the actual position.
  // Watch status().drive == kEnabled. Errors: send failures, kInvalidState.
  virtual Status enable() = 0;
  // Requests every drive to switch off (power stage disabled, brake engaged).
  virtual Status disable() = 0;

  // Commands a new target payout [m] for one winch; the drive moves there at
  // its configured profile speed. Errors: kInvalidArgument (bad index,
  // non-finite), kInvalidState (drive not kEnabled or node dead), send failure.
  virtual Status set_target_payout(int winch, double payout_m) = 0;
  // Commands new targets for all winches at once (payouts_m[0 ..
  // winch_count() - 1]) so that they start and arrive together (a cable
  // robot's cables go slack or overload when one winch runs ahead).
  // Default: set_target_payout() for each, for banks without coordination.
  virtual Status set_target_payouts(const double* payouts_m) {
    for (int i = 0; i < winch_count(); ++i) {
      if (Status s = set_target_payout(i, payouts_m[i]); !s.ok()) return s;
    }
    return Status::Ok();
  }
  // Decelerates every winch to rest and holds, staying enabled (CiA 402 halt
  // bit); a later set_target_payout() clears it.
  virtual Status halt() = 0;
  // Emergency stop of every winch (CiA 402 quick stop); enable() again to move.
  // Sent even to drives in unknown state; an error means a send failed.
  virtual Status quick_stop() = 0;

  // True when every winch is alive, enabled and reports its latest target
  // reached. False right after set_target_payout() until the drive has
  // acknowledged the new target and reached it.
  virtual bool motion_finished() const = 0;
};

}  // namespace cdpr::hal
