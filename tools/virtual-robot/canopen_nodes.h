#pragma once
// The virtual robot's CANopen nodes: per winch one CiA 402 drive (profile
// position mode) and one CiA 406 cable encoder, with exactly the PDO layout
// the drivers expect (drivers/can/canopen.h) and the device side of the
// CiA 402 power state machine (drivers/can/cia402.h), so both ends share
// one definition of the protocol.
//
// Per node: boot-up heartbeat at construction, pre-operational until an NMT
// start, heartbeats every heartbeat_period_us, PDOs only when operational.
// Drives: a rising edge of controlword bit 4 in operation enabled takes the
// target (setpoint acknowledge bit 12 while bit 4 stays high); target
// reached (bit 10) once the winch is there; halt (bit 8), quick stop and
// leaving operation enabled stop the winch where it is.
// Counts: drive position = payout / drive_m_per_count; encoder position =
// (payout + encoder noise) / encoder_m_per_count.
// Time: real monotonic [us] passed in. Not thread-safe.

#include <array>
#include <cstdint>
#include <vector>

#include "drivers/can/can_frame.h"
#include "drivers/can/canopen.h"
#include "drivers/can/cia402.h"
#include "hal/clock.h"
#include "sim/rng.h"
#include "virtual-robot/robot_physics.h"

namespace cdpr::virtual_robot {

struct NodeLayout {
  std::array<int, kCableCount> drive_node_id{1, 2, 3, 4};
  std::array<int, kCableCount> encoder_node_id{11, 12, 13, 14};
  double encoder_m_per_count = 1.0e-5;
  double drive_m_per_count = 1.0e-5;
  hal::TimeUs heartbeat_period_us = 100'000;
  hal::TimeUs pdo_period_us = 10'000;
  double encoder_noise_m = 0.0;  // 1-sigma per reading [m]
};

class CanopenNodes {
 public:
  CanopenNodes(const NodeLayout& layout, RobotPhysics& physics, sim::Rng rng, hal::TimeUs now_us);

  // A frame from the bus (the daemon): NMT or a drive RxPDO; others ignored.
  void on_frame(const drivers::can::CanFrame& frame);
  // Appends the frames due at `now_us` (heartbeats, PDOs).
  void poll(hal::TimeUs now_us, std::vector<drivers::can::CanFrame>& out);

  // Node `id` stops talking (heartbeat and PDOs), as a cut cable would.
  void silence(int node_id, bool silent);

 private:
  struct Node {
    int id = 0;
    drivers::can::NmtState nmt = drivers::can::NmtState::kPreOperational;
    bool boot_up_pending = true;
    bool silent = false;
    hal::TimeUs next_heartbeat_us = 0;
  };
  struct Drive {
    Node node;
    Node encoder;
    drivers::can::cia402::PowerState power = drivers::can::cia402::PowerState::kSwitchOnDisabled;
    std::uint16_t controlword = 0;
    bool setpoint_ack = false;
  };

  void on_rxpdo(int winch, const drivers::can::DriveRxPdo& pdo);
  void on_nmt(const drivers::can::NmtCommandFrame& command);
  void heartbeat(Node& node, hal::TimeUs now_us, std::vector<drivers::can::CanFrame>& out);
  std::uint16_t statusword(int winch) const;

  NodeLayout layout_;
  RobotPhysics& physics_;
  sim::Rng rng_;
  std::array<Drive, kCableCount> drives_{};
  hal::TimeUs next_pdo_us_ = 0;
};

}  // namespace cdpr::virtual_robot
