#pragma once
// What can go wrong with a robot in production, injected into the virtual
// robot at a chosen time (--inject, docs/operation.md): the
// faults the calibration's health watch is for (issue 36).
//
//   slip@T:cable=i,size=d     encoder i slips on its drum by d [m]: from T on
//                             it reads d more for the same cable (the
//                             calibration's offset of cable i is then off by d)
//   anchor@T:cable=i,dx=..,dy=..,dz=..
//                             pulley i's exit point moves by (dx, dy, dz) [m,
//                             world]: the platform settles elsewhere, the
//                             encoders count the same
//   creep@T:cable=i,rate=r    cable i lengthens by r [m/s] from T on (the
//                             same encoder reading, a longer cable)
//   payload@T:mass=m          the platform carries m [kg] more from T on
//
// T is the robot's simulated time [s] since it started (the pose stream's
// stamps). Cables are numbered 0-3 as in robot.toml.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/true_robot.h"
#include "virtual-robot/canopen_nodes.h"
#include "virtual-robot/robot_physics.h"

namespace cdpr::virtual_robot {

struct OperationFault {
  enum class Kind { kEncoderSlip, kAnchorMoved, kCableCreep, kPayload };
  Kind kind = Kind::kEncoderSlip;
  double at_s = 0.0;                               // simulated time it happens [s]
  int cable = 0;                                   // 0..3 (not for payload)
  double size_m = 0.0;                             // slip [m]
  Eigen::Vector3d anchor_shift_m = Eigen::Vector3d::Zero();  // [m, world]
  double rate_mps = 0.0;                           // creep [m/s]
  double mass_kg = 0.0;                            // payload added [kg]
};

// "slip@300:cable=2,size=0.02" -> fault; nullopt and `why` for anything else.
std::optional<OperationFault> parse_operation_fault(const std::string& text, std::string& why);
// One line for the robot's log ("encoder slip of cable 2 by 0.02 m").
std::string describe(const OperationFault& fault);

// The faults of a run, applied when their time comes. A creep moves the
// true offset every kCreepStepS (each step is an equilibrium solve).
class FaultSchedule {
 public:
  static constexpr double kCreepStepS = 1.0;

  explicit FaultSchedule(std::vector<OperationFault> faults) : faults_(std::move(faults)), begun_(faults_.size()) {}
  // Applies what is due at simulated time t_s; the description of each
  // fault that began now is appended to `began`.
  void apply(double t_s, RobotPhysics& physics, CanopenNodes& nodes, std::vector<std::string>& began);

 private:
  std::vector<OperationFault> faults_;
  std::vector<char> begun_;
  std::vector<double> crept_until_s_ = std::vector<double>(faults_.size(), 0.0);
};

}  // namespace cdpr::virtual_robot
