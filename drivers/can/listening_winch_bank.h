#pragma once
// hal::WinchBank as a passive listener on a bus someone else masters (the
// robot's own controller in production: watch mode,
// docs/operation.md). It sends nothing, ever: no NMT, no SDO, no
// heartbeat, no SYNC, no RPDO; there is no send path in this class. It
// reads what the nodes publish for their master:
//
//   heartbeat   0x700 + node       NMT state (alive when fresh and operational)
//   drive TPDO  drive_tpdo_base + node: statusword 0x6041 (UNSIGNED16) at
//               drive_statusword_byte, position actual 0x6064 (INTEGER32)
//               at drive_position_byte (-1: not mapped)
//   encoder TPDO  encoder_tpdo_base + node: position value 0x6004
//               (UNSIGNED32) at encoder_position_byte, unwrapped across
//               [winches.encoder] measuring_range (2^32 when not given)
//
// The defaults are the daemon's own layout (canopen.h, the CiA 402 / 406
// predefined COB-IDs); a controller that maps them elsewhere is described
// by the [operation] keys. Every other frame (the controller's RPDOs, SDOs,
// SYNC, other nodes) is counted as ignored.
// Payout [m] = counts x m_per_count as in CanopenWinchBank; without an
// encoder node the drive's position is the payout. A position jump faster
// than max_speed_mps is a latched fault (reset_faults() clears it).
// Motion commands are refused with kInvalidState: the controller owns the
// drives. Errors, counters, threading: hal/winch_bank.h.

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/can/canopen.h"
#include "drivers/can/canopen_winch_bank.h"
#include "drivers/can/encoder_unwrap.h"

namespace cdpr::drivers::can {

// Where the listener finds each value (above); byte offsets 0..7, -1: not mapped.
struct ListenLayout {
  std::uint32_t drive_tpdo_base = kTpdo1Base;
  int drive_statusword_byte = 0;
  int drive_position_byte = 2;
  std::uint32_t encoder_tpdo_base = kTpdo1Base;
  int encoder_position_byte = 0;
};

// Empty when valid, else the first problem ("encoder_position_byte 6: 4 bytes do not fit a frame").
std::string validate(const ListenLayout& layout);

class ListeningWinchBank final : public hal::WinchBank {
 public:
  ListeningWinchBank(CanWinchBankConfig config, ListenLayout layout, CanConnector connector);

  int winch_count() const override { return static_cast<int>(config_.winches.size()); }
  hal::Status open() override;
  void close() override { transport_.reset(); }
  hal::Status update(hal::TimeUs now_us) override;
  hal::WinchStatus status(int winch) const override;
  std::string fault_text(int winch) const override { return winches_[static_cast<std::size_t>(winch)].fault; }
  hal::WinchBankCounters counters() const override { return counters_; }
  int node_count(int winch) const override;
  hal::NodeStatus node_status(int winch, int node) const override;
  hal::Status reset_faults() override;
  // Refused: kInvalidState ("watch mode: the robot's controller owns the drives").
  hal::Status enable() override { return refused(); }
  hal::Status disable() override { return refused(); }
  hal::Status set_target_payout(int, double) override { return refused(); }
  hal::Status halt() override { return refused(); }
  hal::Status quick_stop() override { return refused(); }
  bool motion_finished() const override { return false; }

 private:
  struct Node {
    int id = 0;
    hal::TimeUs last_heartbeat_us = -1;
    NmtState nmt = NmtState::kBootUp;
    hal::TimeUs last_pdo_us = -1;
  };
  struct Winch {
    Node drive;
    Node encoder;  // id 0: none
    std::uint16_t statusword = 0;
    bool statusword_seen = false;
    EncoderUnwrap unwrap;
    hal::TimeUs position_time_us = -1;
    std::string fault;
  };

  static hal::Status refused();
  void dispatch(const CanFrame& frame, hal::TimeUs now_us);
  void on_position(std::size_t winch, std::uint32_t raw, hal::TimeUs now_us);
  bool alive(const Node& node) const;

  CanWinchBankConfig config_;
  ListenLayout layout_;
  CanConnector connector_;
  std::unique_ptr<CanTransport> transport_;  // receive() only
  std::vector<Winch> winches_;
  hal::TimeUs now_us_ = 0;
  hal::WinchBankCounters counters_;
};

}  // namespace cdpr::drivers::can
