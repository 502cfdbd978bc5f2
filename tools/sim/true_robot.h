#pragma once
// The robot as it really is in a simulation: its geometry with the TRUE
// anchors, the true encoder offsets and the true values of the effects the
// nominal robot.toml does not describe (docs/DESIGN.md "Model terms").

#include <array>
#include <limits>

#include <Eigen/Core>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"

namespace cdpr::sim {

// Defaults mean "effect absent". Each changes the physics or a sensor:
struct HiddenEffects {
  // Cable elasticity: EA [N]; +inf = inextensible. Encoders count unstretched payout.
  double axial_stiffness_n = std::numeric_limits<double>::infinity();
  // Encoder scale s_i: reading = (1 + s_i) * payout + offset_i.
  std::array<double, kCableCount> encoder_scale{};
  // Encoder drift d_i [m] over the run (a slipping encoder): reading of
  // sample k of n += d_i * k / (n - 1), linear in sample order. No model
  // term describes it.
  std::array<double, kCableCount> encoder_drift_m{};
  // Load cell: reading = (1 + gain) * tension + bias.
  double force_bias_n = 0.0;
  double force_gain = 0.0;
  // True centre of mass = nominal + offset [m, platform frame].
  Eigen::Vector3d com_offset_platform = Eigen::Vector3d::Zero();
  // True cable density = nominal * (1 + density_error).
  double density_error = 0.0;
  // Swivel pulley radius [m] (sim/swivel_pulley.h); 0 = plain anchor point.
  double pulley_radius_m = 0.0;
  // The localization's reference point [m, platform frame]: the measured
  // position is the platform origin + R * offset.
  Eigen::Vector3d pose_reference_offset_platform = Eigen::Vector3d::Zero();
  // The "unknown" effect no model term describes: a constant force [N, world]
  // on the platform, acting at its centre of mass (wind).
  Eigen::Vector3d wind_force_world_n = Eigen::Vector3d::Zero();
};

struct TrueRobot {
  // Mass, nominal CoM, nominal cable density, gravity, attachments, reference
  // cable and sensor sigmas as in robot.toml; winches[i].anchor_world is the
  // TRUE pulley exit point. axial_stiffness_n is ignored (effects has EA).
  Robot robot;
  std::array<double, kCableCount> encoder_offset_m{};  // [m] true offsets
  HiddenEffects effects;

  double cable_weight_per_length_npm() const {
    return robot.gravity_mps2 * robot.cable_linear_density_kgpm * (1.0 + effects.density_error);
  }
  Eigen::Vector3d center_of_mass_platform() const {
    return robot.center_of_mass_platform + effects.com_offset_platform;
  }
  double platform_weight_n() const { return robot.platform_mass_kg * robot.gravity_mps2; }
};

// The [effects] table of truth.toml (docs/FORMATS.md): only effects that are
// present, by name: axial_stiffness [N], encoder_scale (4), encoder_drift (4) [m], force_bias [N],
// force_gain, com_offset (3) [m], density_error, pulley_radius [m],
// pose_reference_offset (3) [m], wind_force (3) [N].
EffectValues effect_values(const HiddenEffects& effects);

// truth.toml content: true anchors, offsets and effects.
Truth truth_of(const TrueRobot& robot);

// The effects an [effects] table names (the inverse of effect_values; a
// name it does not know, or a value of the wrong size, is left absent).
HiddenEffects hidden_effects_of(const EffectValues& values);

// The robot a fitted calibration says `nominal` is: its anchors, offsets
// and effect values as the truth. Predicting readings with it (noiseless
// sim/sensors.h measure) is what the fit expects at a pose it has not seen.
TrueRobot robot_of(const Robot& nominal, const Calibration& calibration);

}  // namespace cdpr::sim
