#pragma once
// The TRUE static equilibrium of the robot with heavy (optionally elastic)
// cables, found numerically (sim/equilibrium_model.h): an independent model
// like the paper's finite-element reference (Sec. V-A), never the fitting
// model of solver/ run backwards.
//
// Both problems run damped Newton (full-pivot LU steps, backtracking line
// search on the squared scaled equations) and report failure as a value;
// nothing here aborts or throws on a bad pose.

#include <array>

#include <Eigen/Core>

#include "sim/equilibrium_state.h"
#include "sim/true_robot.h"
#include "solver/nls/pose.h"
#include "src/formats/expected.h"

namespace cdpr::sim {

struct SolverOptions {
  int segments = 2000;       // Simpson segments per cable (sim/cable_shooting.h)
  int max_iterations = 60;   // Newton iterations
  // Converged when every scaled equation is below this: forces below
  // tolerance * platform weight [N], lengths below tolerance [m].
  double tolerance = 1e-11;
};

using EquilibriumResult = Expected<Equilibrium, EquilibriumFailure>;

// Inverse problem: the platform origin at `position_world` with heading
// `yaw_rad`; finds roll, pitch, every cable's force and unstretched length.
// Starts from the rigid-cable statics (min-norm tensions, the platform level).
EquilibriumResult solve_equilibrium(const TrueRobot& robot, const Eigen::Vector3d& position_world, double yaw_rad,
                                    const SolverOptions& options = {});

// Forward problem: the winches hold `payout_m` (unstretched cable from each
// anchor point A over its pulley to the attachment, CableEquilibrium::payout_m);
// finds the pose and cable forces in equilibrium, by Newton from the
// equilibrium at `initial` (position and yaw; its roll and pitch are ignored).
// An underconstrained robot may have several equilibria: this returns the one
// Newton reaches from `initial`.
// With `slack` cables the platform hangs on the others alone: the slack
// ones carry no force and must be at least as long as their chords in the
// result (else kSlackCable: that cable would be taut). Newton then starts
// from the rigid-cable force balance of the taut cables at `initial`.
EquilibriumResult solve_forward_equilibrium(const TrueRobot& robot, const std::array<double, kCableCount>& payout_m,
                                            const Pose& initial, const SolverOptions& options = {},
                                            const SlackCables& slack = {});

const char* to_string(EquilibriumError error);

}  // namespace cdpr::sim
