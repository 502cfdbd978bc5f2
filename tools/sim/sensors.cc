#include "sim/sensors.h"

namespace cdpr::sim {
namespace {

Eigen::Vector3d normal3(Rng& rng, double sigma) {
  const double x = rng.normal(), y = rng.normal(), z = rng.normal();
  return sigma * Eigen::Vector3d(x, y, z);
}

}  // namespace

Sample measure(const TrueRobot& robot, const Equilibrium& state, double noise_scale, Rng& rng, int sample_id) {
  const NoiseSigmas& sigma = robot.robot.noise;
  const HiddenEffects& effects = robot.effects;
  Sample sample;
  sample.id = sample_id;
  // Fixed draw order (position, rotation, encoders, force) keeps a seed's
  // numbers the same whatever the values.
  const Pose& pose = state.world_T_platform;
  sample.position_world = pose.transform(effects.pose_reference_offset_platform) +
                          normal3(rng, noise_scale * sigma.position_m);
  const Eigen::Vector3d rotation_noise = normal3(rng, noise_scale * sigma.orientation_rad);
  sample.world_R_platform = (state.world_T_platform.world_R_platform * so3_exp(rotation_noise)).normalized();
  for (int i = 0; i < kCableCount; ++i) {
    sample.encoder_m[i] = (1.0 + effects.encoder_scale[i]) * state.cables[i].payout_m + robot.encoder_offset_m[i] +
                          noise_scale * sigma.encoder_m * rng.normal();
  }
  const double tension = state.cables[robot.robot.reference_cable].tension_n;
  sample.force_n = force_reading_n(effects, tension) + noise_scale * sigma.force_n * rng.normal();
  return sample;
}

double force_reading_n(const HiddenEffects& effects, double tension_n) {
  return (1.0 + effects.force_gain) * tension_n + effects.force_bias_n;
}

}  // namespace cdpr::sim
