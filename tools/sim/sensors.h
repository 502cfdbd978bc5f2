#pragma once
// What the robot's sensors read at a true equilibrium (one samples.csv row).
//
//   enc_i  = (1 + s_i) * payout_i + offset_i + N(0, (k sigma_enc)^2)
//            payout_i = CableEquilibrium::payout_m: unstretched cable from the
//            anchor point A over the pulley (if any) to the attachment. The
//            encoders count unstretched cable (docs/DESIGN.md); for inextensible
//            cables this IS the true arc length from A to the attachment
//            (free catenary + wrapped pulley arc), as docs/FORMATS.md defines.
//   force  = (1 + gain) * |F_b,ref| + bias + N(0, (k sigma_force)^2)
//            |F_b,ref|: tension of the reference cable at its attachment.
//   position    = true + N(0, (k sigma_pos)^2 I)
//   orientation = true * Exp(xi), xi ~ N(0, (k sigma_rot)^2 I): a rotation
//                 vector in the platform frame (the right perturbation of
//                 solver/nls/pose.h; the paper's exp of a twist, split into its
//                 translation and rotation parts).
// s_i, gain, bias from the robot's hidden effects, offsets from the robot,
// sigmas from robot.noise, k = noise_scale (0: noiseless).

#include "sim/equilibrium_state.h"
#include "sim/rng.h"
#include "sim/true_robot.h"
#include "solver/model/sample.h"

namespace cdpr::sim {

Sample measure(const TrueRobot& robot, const Equilibrium& state, double noise_scale, Rng& rng, int sample_id);

// The load cell's noiseless reading of a true tension [N]: (1 + gain) *
// tension + bias, with the robot's hidden gain and bias. The virtual robot's
// live load cell reads through this too.
double force_reading_n(const HiddenEffects& effects, double tension_n);

}  // namespace cdpr::sim
