#pragma once
// The device side of a CAN bus for driver loopback tests: CiA 402 drives in
// profile position mode and CiA 406 cable encoders geared to them, speaking
// the PDO mapping of drivers/can/canopen.h over a real socket (the far end of
// a socketpair or an accepted Unix connection). Nodes boot, send boot-up and
// heartbeats, obey NMT, walk the CiA 402 power state machine from
// controlwords, run the new-setpoint handshake and move their position
// towards the target at a fixed speed as test time passes in step(now).
// Silencing a node stops all its output, as a pulled connector would.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "drivers/can/canopen.h"
#include "drivers/can/cia402.h"
#include "drivers/can/fd_can_transport.h"

namespace cdpr::drivers::can::test {

class FakeCanopenBus {
 public:
  struct Drive {
    int node_id = 0;
    int encoder_node_id = 0;             // 0: none
    std::int32_t encoder_per_drive = 2;  // encoder counts per drive count
    std::int32_t encoder_offset = 1000;  // encoder counts at drive position 0
    double speed_counts_per_s = 20000.0;
    // State (read by tests).
    NmtState nmt = NmtState::kPreOperational;
    cia402::PowerState power = cia402::PowerState::kSwitchOnDisabled;
    std::uint16_t controlword = 0;
    double position_counts = 0.0;
    std::int32_t target_counts = 0;
    bool setpoint_ack = false;
    bool silent = false;
    hal::TimeUs booted_us = -1;  // not booted yet: sends boot-up at first step
  };

  FakeCanopenBus(int fd, hal::TimeUs heartbeat_period_us = 100'000, hal::TimeUs pdo_period_us = 10'000)
      : transport_(fd, "fake bus"), heartbeat_period_us_(heartbeat_period_us), pdo_period_us_(pdo_period_us) {
    drives_.reserve(16);  // references from add() stay valid
  }

  Drive& add(int node_id, int encoder_node_id) {
    drives_.push_back(Drive{});
    drives_.back().node_id = node_id;
    drives_.back().encoder_node_id = encoder_node_id;
    return drives_.back();
  }
  Drive& drive(std::size_t i) { return drives_[i]; }
  std::int32_t encoder_counts(const Drive& d) const {
    return static_cast<std::int32_t>(std::llround(d.position_counts)) * d.encoder_per_drive + d.encoder_offset;
  }
  int frames_received() const { return frames_received_; }

  // Handles everything received, moves, and sends what is due at `now_us`.
  void step(hal::TimeUs now_us) {
    CanFrame frame;
    for (;;) {
      const hal::Result<bool> got = transport_.receive(frame, 0);
      if (!got.ok() || !got.value()) break;
      ++frames_received_;
      for (Drive& d : drives_) handle(d, frame);
    }
    const double dt_s = last_step_us_ < 0 ? 0.0 : 1e-6 * static_cast<double>(now_us - last_step_us_);
    last_step_us_ = now_us;
    for (Drive& d : drives_) {
      move(d, dt_s);
      if (d.silent) continue;
      if (d.booted_us < 0) {
        d.booted_us = now_us;
        send_all(d, make_heartbeat(d.node_id, NmtState::kBootUp), make_heartbeat(d.encoder_node_id, NmtState::kBootUp));
      }
    }
    if (now_us - last_heartbeat_us_ >= heartbeat_period_us_) {
      last_heartbeat_us_ = now_us;
      for (Drive& d : drives_) {
        if (!d.silent) send_all(d, make_heartbeat(d.node_id, d.nmt), make_heartbeat(d.encoder_node_id, d.nmt));
      }
    }
    if (now_us - last_pdo_us_ >= pdo_period_us_) {
      last_pdo_us_ = now_us;
      for (Drive& d : drives_) {
        if (d.silent || d.nmt != NmtState::kOperational) continue;
        send_all(d, make_drive_txpdo(d.node_id, statusword(d), static_cast<std::int32_t>(std::llround(d.position_counts))),
                 make_encoder_tpdo(d.encoder_node_id, encoder_counts(d)));
      }
    }
  }

  std::uint16_t statusword(const Drive& d) const {
    std::uint16_t sw = cia402::statusword_of(d.power);
    const bool halted = (d.controlword & cia402::kCwHalt) != 0;
    const bool at_target = std::llround(d.position_counts) == d.target_counts;
    if (d.power == cia402::PowerState::kOperationEnabled && (at_target || halted)) sw |= cia402::kSwTargetReached;
    if (d.setpoint_ack) sw |= cia402::kSwSetpointAcknowledge;
    return sw;
  }

 private:
  void send_all(const Drive& d, const CanFrame& drive_frame, const CanFrame& encoder_frame) {
    (void)transport_.send(drive_frame);
    if (d.encoder_node_id != 0) (void)transport_.send(encoder_frame);
  }

  void handle(Drive& d, const CanFrame& frame) {
    if (d.silent) return;
    if (auto nmt = parse_nmt(frame)) {
      if (nmt->node_id != 0 && nmt->node_id != d.node_id && nmt->node_id != d.encoder_node_id) return;
      if (nmt->command == NmtCommand::kStart) d.nmt = NmtState::kOperational;
      if (nmt->command == NmtCommand::kStop) d.nmt = NmtState::kStopped;
      if (nmt->command == NmtCommand::kEnterPreOperational) d.nmt = NmtState::kPreOperational;
      return;
    }
    if (node_of(frame, kRpdo1Base) != d.node_id || d.nmt != NmtState::kOperational) return;
    const auto pdo = parse_drive_rxpdo(frame);
    if (!pdo) return;
    const std::uint16_t previous = d.controlword;
    d.controlword = pdo->controlword;
    const cia402::PowerState before = d.power;
    d.power = cia402::next_power_state(d.power, pdo->controlword, previous);
    if (d.power == cia402::PowerState::kOperationEnabled && before != d.power) {
      d.target_counts = static_cast<std::int32_t>(std::llround(d.position_counts));
    }
    const bool new_setpoint = (pdo->controlword & cia402::kCwNewSetpoint) != 0;
    if (d.power == cia402::PowerState::kOperationEnabled && new_setpoint &&
        (previous & cia402::kCwNewSetpoint) == 0) {
      d.target_counts = pdo->target_counts;
      d.setpoint_ack = true;
    }
    if (!new_setpoint) d.setpoint_ack = false;
  }

  void move(Drive& d, double dt_s) {
    if (d.power != cia402::PowerState::kOperationEnabled || (d.controlword & cia402::kCwHalt) != 0) return;
    const double error = static_cast<double>(d.target_counts) - d.position_counts;
    const double step = d.speed_counts_per_s * dt_s;
    d.position_counts += error > step ? step : error < -step ? -step : error;
  }

  FdCanTransport transport_;
  hal::TimeUs heartbeat_period_us_;
  hal::TimeUs pdo_period_us_;
  hal::TimeUs last_step_us_ = -1;
  hal::TimeUs last_heartbeat_us_ = -1'000'000'000;
  hal::TimeUs last_pdo_us_ = -1'000'000'000;
  std::vector<Drive> drives_;
  int frames_received_ = 0;
};

}  // namespace cdpr::drivers::can::test
