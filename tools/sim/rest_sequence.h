#pragma once
// A robot in operation, for the health watch offline (docs/operation.md):
// a sequence of rests at random points of the preset's workspace, as a
// production controller's point-to-point moves leave them, with one fault
// injected from a chosen rest on:
//   slip     the encoder of `cable` slips on its drum: its offset + size [m]
//   anchor   the pulley of `cable` is moved by size [m] in a random direction
//   creep    `cable` creeps: it grows longer than its encoder counts, by
//            size [m] at its payout at the fault's first rest, linearly over
//            ramp_rests rests (a strain: encoder scale -size / payout)
//   payload  the platform carries size [kg] more, its centre of mass moved
//            by com_shift [m, platform frame]
// The true robot is make_true_robot(robot): the same seed gives the robot a
// calibration data set of that seed was measured on. Reproducible.

#include <cstdint>
#include <string_view>
#include <optional>
#include <vector>

#include "sim/dataset.h"
#include "sim/equilibrium_state.h"
#include "sim/true_robot.h"
#include "solver/model/sample.h"
#include "src/formats/expected.h"

namespace cdpr::sim {

enum class FaultKind { kNone, kEncoderSlip, kAnchorMoved, kCableCreep, kPayloadChange };
std::optional<FaultKind> parse_fault_kind(std::string_view name);  // none slip anchor creep payload

struct InjectedFault {
  FaultKind kind = FaultKind::kNone;
  int from_rest = 0;  // the first rest with the fault
  int cable = 0;
  double size = 0.0;  // m (slip, anchor, creep) or kg (payload)
  Eigen::Vector3d com_shift_platform = Eigen::Vector3d::Zero();  // payload
  Eigen::Vector3d direction_world = Eigen::Vector3d::Zero();     // anchor: the move's direction (zero: random)
  int ramp_rests = 10;  // creep
};

struct RestSequenceConfig {
  DatasetConfig robot;  // preset, seed (the true robot), noise, effects
  int rest_count = 100;
  InjectedFault fault;
};

struct RestSequence {
  Robot nominal;                    // robot.toml
  TrueRobot true_robot;             // before the fault
  std::vector<Sample> rests;        // samples.csv, ids 0..n-1
  std::vector<Equilibrium> states;  // the true state of each rest
  Eigen::Vector3d anchor_shift_world = Eigen::Vector3d::Zero();  // an anchor fault's displacement
};

Expected<RestSequence, std::string> simulate_rest_sequence(const RestSequenceConfig& config);

// The true robot at rest `k` of the sequence (the fault applied from its rest on).
TrueRobot robot_at_rest(const RestSequence& sequence, const InjectedFault& fault, int k);

}  // namespace cdpr::sim
