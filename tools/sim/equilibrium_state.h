#pragma once
// The true static state of the robot at one pose, as the simulator finds it
// (sim/equilibrium.h): what a model check compares the fitting model with.

#include <array>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "solver/nls/pose.h"
#include "solver/model/robot.h"

namespace cdpr::sim {

// Which cables hang slack: a slack cable carries no force (its own weight
// on the platform is neglected) and is at least as long as its chord.
using SlackCables = std::array<bool, kCableCount>;

struct CableEquilibrium {
  Eigen::Vector3d attachment_world = Eigen::Vector3d::Zero();  // [m]
  double h_n = 0.0;        // [N] horizontal force on the platform, towards the anchor (> 0)
  double v_n = 0.0;        // [N] vertical force on the platform, up positive
  double tension_n = 0.0;  // [N] |(h, v)|: what a load cell at the attachment feels
  // Unstretched length of the free (sagging) cable, pulley departure to attachment [m].
  double free_unstretched_m = 0.0;
  // Unstretched cable from the anchor point A over the pulley to the
  // attachment [m]: what the winch pays out (equals free_unstretched_m without pulley).
  double payout_m = 0.0;
  double free_arc_m = 0.0;     // [m] true (stretched) length of the free cable
  double wrapped_arc_m = 0.0;  // [m] geometric cable length on the pulley (0 without pulley)
  double arc_length_m = 0.0;   // [m] free_arc + wrapped_arc: true cable length from A to the attachment
  bool slack = false;          // no tension: h, v, tension 0, the lengths all payout_m
};

struct Equilibrium {
  Pose world_T_platform;  // true pose; rotation = Rz(yaw) Ry(pitch) Rx(roll)
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;
  std::array<CableEquilibrium, kCableCount> cables;
  // Remaining imbalance of the solution (small multiples of round-off).
  double force_residual_n = 0.0;    // |sum of forces on the platform|
  double moment_residual_nm = 0.0;  // |sum of moments about the platform origin|
  double length_residual_m = 0.0;   // largest miss of a cable end at its pulley
  int iterations = 0;               // Newton iterations
};

enum class EquilibriumError {
  kVerticalCable,   // an attachment is straight below its anchor: the cable plane is undefined
  kInfeasible,      // the rigid-cable statics need a pushing cable at this pose
  kSlackCable,      // the solution has a cable without tension
  kNoConvergence,   // Newton did not reach the tolerance (or its line search stalled)
  kUnstable,        // converged to an implausible posture (tilt beyond 60 degrees)
};

struct EquilibriumFailure {
  EquilibriumError code = EquilibriumError::kNoConvergence;
  std::string message;
};

// A failure of the given kind, saying why.
inline EquilibriumFailure failure(EquilibriumError code, std::string message) { return {code, std::move(message)}; }

}  // namespace cdpr::sim
