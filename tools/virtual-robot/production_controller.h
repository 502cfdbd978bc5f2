#pragma once
// The robot's own production controller, as the virtual robot plays it in
// operation (--operate): it owns the drives and moves the platform through
// jobs by itself, random point-to-point moves with rests of a few seconds,
// while cdpr-calibd may only listen (watch mode, docs/operation.md).
//
// A CANopen master of its own on the robot's bus: at start it commissions
// every node over SDO (expedited, size unspecified) the way the daemon's
// configuration lays them out (drives: TPDO1 = statusword 0x6041 +
// position actual 0x6064 on 0x180 + node, RPDO1 = controlword 0x6040 +
// target 0x607A on 0x200 + node, profile position mode; encoders: TPDO1 =
// position 0x6004 on 0x180 + node; every TPDO type 254 with a 20 ms event
// timer, heartbeats every 100 ms), starts them (NMT) and enables the drives.
// Then per move: a target position drawn uniformly in the preset's
// workspace (shrunk by `margin` of its size on every side), heading 0, its
// payouts from the true statics (the controller is perfectly calibrated at
// the start: what changes afterwards, --inject, it does not know), each
// drive's profile scaled so that all arrive together (0x6081/0x6083/0x6084
// by SDO), the targets by RPDO with the set-point handshake. A rest of a
// random length follows once every drive is still.
// Every frame it sends goes to the nodes and onto the bus, where a
// listener sees it as on a real bus. Time: simulated seconds. Not thread-safe.

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/can/can_frame.h"
#include "sim/presets.h"
#include "sim/rng.h"
#include "sim/true_robot.h"
#include "virtual-robot/canopen_nodes.h"

namespace cdpr::virtual_robot {

struct OperationOptions {
  bool enabled = false;
  double rest_min_s = 4.0;   // rest after each move [s, simulated], drawn uniformly in [min, max]
  double rest_max_s = 8.0;
  double margin = 0.2;       // fraction of the workspace box kept clear on each side
  double winch_speed_mps = 1.0;  // the longest cable's profile speed [m/s]
  double acceleration_mps2 = 0.5;
};

class ProductionController {
 public:
  ProductionController(const OperationOptions& options, const sim::TrueRobot& model, sim::Preset preset,
                       const NodeLayout& layout, int segments, sim::Rng rng,
                       const std::array<double, kCableCount>& start_payout_m);

  // What the controller does at simulated time t_s: the frames it sends,
  // appended to `out` (the caller hands them to the nodes and the bus).
  void step(double t_s, CanopenNodes& nodes, std::vector<drivers::can::CanFrame>& out);

  int moves() const { return moves_; }
  // Rests begun after a move (the platform then hangs still for rest_min_s or more).
  int rests() const { return rests_; }
  // Targets for which the statics found no rest pose (another is drawn).
  int unreachable() const { return unreachable_; }

 private:
  enum class Phase { kCommission, kResting, kStarting, kMoving };

  void commission(std::vector<drivers::can::CanFrame>& out) const;
  // Plans the next move and sends its profiles and targets; false when no target was found.
  bool start_move(std::vector<drivers::can::CanFrame>& out);
  void send_targets(std::uint16_t controlword, std::vector<drivers::can::CanFrame>& out) const;

  OperationOptions options_;
  sim::TrueRobot model_;
  sim::PresetSpec spec_;
  NodeLayout layout_;
  int segments_;
  sim::Rng rng_;
  Phase phase_ = Phase::kCommission;
  double until_s_ = 0.0;
  std::array<std::int32_t, kCableCount> target_counts_{};
  std::array<double, kCableCount> payout_m_{};  // where the drives were sent last [m, encoder units]
  int moves_ = 0, rests_ = 0, unreachable_ = 0;
};

}  // namespace cdpr::virtual_robot
