#pragma once
// The Jacobian blocks of model terms (solver/model/effects.h) that a base
// catenary fit (no terms) lacks, added at 0, at the fit's values: what
// EffectPoseFactor with those terms gives for their blocks there (whitened,
// the row's left-out readings zeroed, after the loss), from the base
// model's statics and catenary alone. At 0 no term changes the cable: the
// elastic catenary over a pulley (solver/model/effect_cable.h) is the plain
// one of Eq. (1)-(4), and each term's derivative there has a closed form in
// the plain catenary's quantities. The score test of missing terms
// (term_tests.h) takes the fit's own columns from its last linearisation
// and needs only these beside them.

#include <array>
#include <vector>

#include <Eigen/Core>

#include "solver/model/effects.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "solver/nls/loss.h"
#include "solver/nls/pose.h"

namespace cdpr {

// One row's fitted values: its pose and reference force, the anchors and offsets.
struct BaseFitRow {
  const Sample& sample;
  const Pose& world_T_platform;
  const Eigen::Vector2d& reference_force;
  const std::array<Eigen::Vector3d, kCableCount>& anchor_world;
  const std::array<double, kCableCount>& offset_m;
};

// Writes one block per term of `effects` (EffectPoseFactor::kResidualDim x
// effect_dimension, row-major) to `jacobians`, as EffectPoseFactor(robot,
// ., row.sample, height_sigma_m, loss, effects) evaluated with every term
// at 0 would, to rounding. False where the base model cannot be evaluated.
// Allocates nothing.
bool absent_term_jacobians(const Robot& robot, const BaseFitRow& row, double height_sigma_m, const Loss& loss,
                           const std::vector<Effect>& effects, double* const* jacobians);

}  // namespace cdpr
