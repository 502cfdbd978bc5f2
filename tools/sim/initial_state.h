#pragma once
// A starting point for the equilibrium Newton (sim/equilibrium.h) at a given
// position and yaw, with the platform level: rigid-cable statics give the
// tensions, then each cable alone is shot onto its pulley. The model's slack
// cables (EquilibriumModel::set_slack) take no part: the taut ones balance
// the platform's weight alone (force balance only), and a slack cable's
// state is h = v = 0 with its free length and payout the chord.

#include <Eigen/Core>

#include "sim/equilibrium_model.h"
#include "src/formats/expected.h"

namespace cdpr::sim {

// Each cable's rows hold to `tolerance_m` at the result. Fails with
// kVerticalCable, kInfeasible (a rigid tension <= 0) or kNoConvergence (a
// cable could not be shot onto its pulley).
Expected<State, EquilibriumFailure> initial_state(EquilibriumModel& model, const Eigen::Vector3d& position_world,
                                                  double yaw_rad, double tolerance_m);

}  // namespace cdpr::sim
