#include "cdpr-accuracy/model_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/dataset.h"
#include "solver/model/cable_prediction.h"

namespace cdpr::accuracy {

ModelCheck model_check(sim::Preset preset, int poses, std::uint64_t seed) {
  ModelCheck check;
  sim::DatasetConfig config;
  config.preset = preset;
  config.pose_count = poses;
  config.seed = seed;
  config.noise_scale = 0.0;
  const auto data = sim::simulate_dataset(config);
  if (!data) {
    check.error = data.error();
    return check;
  }
  const Robot& robot = data->true_robot.robot;
  std::array<Eigen::Vector3d, kCableCount> anchors;
  for (int i = 0; i < kCableCount; ++i) anchors[i] = robot.winches[i].anchor_world;
  check.min_length_m = check.min_force_n = std::numeric_limits<double>::infinity();
  int lengths = 0, forces = 0;
  for (const sim::Equilibrium& state : data->states) {
    const sim::CableEquilibrium& ref = state.cables[robot.reference_cable];
    const auto predicted = predict_cables(robot, anchors, state.world_T_platform, Eigen::Vector2d(ref.h_n, ref.v_n));
    if (!predicted) {
      check.error = "the fitting model cannot be evaluated at a simulated equilibrium";
      return check;
    }
    for (int i = 0; i < kCableCount; ++i) {
      const sim::CableEquilibrium& truth = state.cables[i];
      const double length_pct = 100.0 * std::abs((*predicted)[i].arc_length_m - truth.arc_length_m) / truth.arc_length_m;
      check.mean_length_error_pct += length_pct;
      check.max_length_error_pct = std::max(check.max_length_error_pct, length_pct);
      ++lengths;
      check.min_length_m = std::min(check.min_length_m, truth.arc_length_m);
      check.max_length_m = std::max(check.max_length_m, truth.arc_length_m);
      check.min_force_n = std::min(check.min_force_n, truth.tension_n);
      check.max_force_n = std::max(check.max_force_n, truth.tension_n);
      if (i == robot.reference_cable) continue;  // an input of the check, not a prediction
      const double force_pct = 100.0 * std::abs((*predicted)[i].tension_n - truth.tension_n) / truth.tension_n;
      check.mean_force_error_pct += force_pct;
      check.max_force_error_pct = std::max(check.max_force_error_pct, force_pct);
      ++forces;
    }
  }
  check.poses = static_cast<int>(data->states.size());
  check.mean_length_error_pct /= std::max(lengths, 1);
  check.mean_force_error_pct /= std::max(forces, 1);
  return check;
}

}  // namespace cdpr::accuracy
