#pragma once
// How noisy each sensor group of a final catenary fit really is, against
// the sigma robot.toml states: variance-component estimation (Helmert's,
// the REML estimate of one scale per group at the fit).
//
// With J the whitened Jacobian of the fit (every pose, reference force,
// anchor, offset and model term) and H = J (J'J)^-1 J' its hat matrix, a
// row's redundancy 1 - h_ii is its share of the degrees of freedom: the
// residual r_i of a right model with a right sigma has E[r_i^2] = 1 - h_ii.
// So per group g
//   scale_g^2 = sum_g r_i^2 / sum_g (1 - h_ii)
// is the implied sigma over the stated one (1 when robot.toml is right),
// and sum_g r_i^2 is tested against chi-square(sum_g (1 - h_ii)).
// Refitting with the group's sigma times scale_g lowers -2 log L by
//   chi2_g - red_g - red_g log(chi2_g / red_g)    (>= 0)
// to first order: the likelihood-ratio statistic of one more parameter,
// comparable with a model term's chi-square drop (docs/diagnosis.md).
//
// The pose's own rows carry most of a pose's unknowns: a group whose
// redundancy is small (a few rows' worth) says little, and the test says so
// by its p. Rows left out as gross errors are not in any group.

#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/calibration/noise_scale.h"

namespace cdpr {

// Per group, in NoiseGroup order; groups without rows are left out. Empty
// when the fit failed, is rigid, or its information matrix is singular.
// Runs after the fit; allocates.
std::vector<NoiseComponent> noise_components(const Robot& robot, const CalibrationOptions& options,
                                             const CalibrationResult& result);

// Multiplies the sigma of `group` by `factor` where a fit reads it: robot.toml's
// [noise] and the rows' own sigmas, or options.height_sigma_m for the
// height consistency.
void scale_noise(NoiseGroup group, double factor, Robot& robot, std::vector<Sample>& samples,
                 CalibrationOptions& options);

}  // namespace cdpr
