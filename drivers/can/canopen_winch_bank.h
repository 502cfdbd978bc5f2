#pragma once
// hal::WinchBank over CANopen: per winch one CiA 402 drive (profile position
// mode) and optionally one CiA 406 cable encoder, with the PDO mapping of
// drivers/can/canopen.h, on any CanTransport (SocketCAN or the virtual
// robot's Unix socket: the protocol code is the same).
//
// Per node: a heartbeat consumer (alive when heard within
// heartbeat_timeout_us; a boot-up or pre-operational heartbeat gets an NMT
// start, rate-limited to one per resend interval) and, for drives, a
// Cia402Drive state machine. A drive that reboots (boot-up heartbeat) is
// started again but NOT re-enabled: it shows kDisabled until enable().
//
// Units: payout [m] = encoder counts x encoder_m_per_count (the encoder's
// zero is the payout zero; the calibration estimates the offset). Targets go
// to the drive relative to the present: target_counts = actual_counts +
// round((target_m - payout_m) / drive_m_per_count), so motor and cable
// encoder need not share a zero. Without an encoder node the drive's own
// position is the payout (then the mapping is exact).
//
// Errors, counters, allocation: see hal/winch_bank.h. update() reads at most
// max_frames_per_update frames, so a babbling bus cannot starve the loop.
// The transport is made by the connector at open(), so open() after a lost
// connection reconnects.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "drivers/can/can_transport.h"
#include "drivers/can/cia402_drive.h"
#include "hal/winch_bank.h"

namespace cdpr::drivers::can {

struct CanWinchConfig {
  int drive_node_id = 0;             // 1..127
  int encoder_node_id = 0;           // 1..127, != drive; 0: no encoder node, use the drive's position
  double encoder_m_per_count = 0.0;  // payout [m] per encoder count, sign gives direction; != 0
  double drive_m_per_count = 0.0;    // payout [m] per drive position count; != 0
};

struct CanWinchBankConfig {
  std::vector<CanWinchConfig> winches;
  hal::TimeUs heartbeat_timeout_us = 500'000;  // consumer heartbeat time (>= 1.5 x producer period)
  hal::TimeUs resend_interval_us = 100'000;    // NMT start / controlword resend when nothing moves on
  int max_frames_per_update = 256;
};

using CanConnector = std::function<hal::Result<std::unique_ptr<CanTransport>>()>;

// "socketcan:can0" or "unix:/run/robot/can.sock" -> connector. Anything else:
// a connector that fails with kInvalidArgument.
CanConnector make_can_connector(const std::string& endpoint);

// Empty when valid, else the first problem ("winch 2: drive node id 0 out of 1..127").
std::string validate(const CanWinchBankConfig& config);

class CanopenWinchBank final : public hal::WinchBank {
 public:
  CanopenWinchBank(CanWinchBankConfig config, CanConnector connector);

  int winch_count() const override { return static_cast<int>(config_.winches.size()); }
  hal::Status open() override;
  void close() override;
  hal::Status update(hal::TimeUs now_us) override;
  hal::WinchStatus status(int winch) const override;
  hal::WinchBankCounters counters() const override { return counters_; }
  hal::Status enable() override;
  hal::Status disable() override;
  hal::Status set_target_payout(int winch, double payout_m) override;
  hal::Status halt() override;
  hal::Status quick_stop() override;
  bool motion_finished() const override;

 private:
  struct Node {
    int id = 0;
    hal::TimeUs last_heartbeat_us = -1;
    NmtState nmt_state = NmtState::kBootUp;
    bool start_wanted = false;
    hal::TimeUs last_start_sent_us = -1;
  };
  struct Winch {
    Node drive_node;
    Node encoder_node;  // id 0: none
    Cia402Drive drive;
    std::int32_t encoder_counts = 0;
    bool encoder_valid = false;
    hal::TimeUs encoder_time_us = 0;
    double target_payout_m = 0.0;
  };

  hal::Status send(const CanFrame& frame);
  void dispatch(const CanFrame& frame, hal::TimeUs now_us);
  void on_heartbeat(Winch& winch, Node& node, NmtState state, hal::TimeUs now_us);
  hal::Status service_node(Node& node, hal::TimeUs now_us);
  // Sends what the drive state machines want now; first error wins.
  hal::Status poll_drives(hal::TimeUs now_us);
  hal::Status set_goal_all(Cia402Drive::Goal goal);
  bool node_alive(const Node& node) const;
  double payout_m(const Winch& winch) const;
  hal::Status check_open() const;

  CanWinchBankConfig config_;
  CanConnector connector_;
  std::unique_ptr<CanTransport> transport_;
  std::vector<Winch> winches_;
  hal::TimeUs now_us_ = 0;
  hal::WinchBankCounters counters_;
};

}  // namespace cdpr::drivers::can
