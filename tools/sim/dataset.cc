#include "sim/dataset.h"

#include <algorithm>

#include "sim/rng.h"
#include "sim/sensors.h"
#include "sim/stream_purpose.h"
#include "sim/waypoints.h"
#include "solver/calibration/pose_design.h"

namespace cdpr::sim {
namespace {

// A direction uniform on the sphere, times `norm`.
Eigen::Vector3d random_vector(Rng& rng, double norm) {
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
  } while (v.norm() < 1e-12);
  return norm * v.normalized();
}

Robot nominal_robot(const TrueRobot& truth, const DatasetConfig& config) {
  Robot nominal = truth.robot;
  nominal.noise = preset_spec(config.preset).robot.robot.noise;  // the truth's may be noisier than stated
  Rng rng = Rng::stream(config.seed, kStreamAnchorPerturbation);
  for (Winch& winch : nominal.winches) winch.anchor_world += random_vector(rng, config.anchor_perturbation_m);
  if (config.noise_scale > 0.0) {
    nominal.noise.encoder_m *= config.noise_scale;
    nominal.noise.force_n *= config.noise_scale;
    nominal.noise.position_m *= config.noise_scale;
    nominal.noise.orientation_rad *= config.noise_scale;
  }
  nominal.axial_stiffness_n.reset();  // elasticity is a hidden effect
  return nominal;
}

bool taut_enough(const Equilibrium& state, double min_tension_n) {
  return std::all_of(state.cables.begin(), state.cables.end(),
                     [&](const CableEquilibrium& c) { return c.tension_n >= min_tension_n; });
}

}  // namespace

TrueRobot make_true_robot(const DatasetConfig& config) {
  const PresetSpec spec = preset_spec(config.preset);
  TrueRobot robot = spec.robot;
  robot.effects = config.effects;
  robot.robot.noise.orientation_rad *= config.orientation_noise_factor;
  Rng rng = Rng::stream(config.seed, kStreamEncoderOffsets);
  for (double& offset : robot.encoder_offset_m) offset = rng.uniform(-spec.offset_range_m, spec.offset_range_m);
  return robot;
}

Expected<SimulatedDataset, std::string> simulate_dataset(const DatasetConfig& config) {
  if (config.pose_count < 1) return Unexpected{std::string("pose count must be at least 1")};
  if (config.segments < 1) return Unexpected{std::string("segments must be at least 1")};
  PresetSpec spec = preset_spec(config.preset);
  if (config.workspace_min && config.workspace_max) {
    spec.workspace_min = *config.workspace_min;
    spec.workspace_max = *config.workspace_max;
  }
  SimulatedDataset data;
  data.true_robot = make_true_robot(config);
  data.nominal = nominal_robot(data.true_robot, config);
  data.truth = truth_of(data.true_robot);

  SolverOptions options;
  options.segments = config.segments;
  WaypointSequence waypoints(spec, config.seed);
  const int wanted = std::max(config.pose_count, config.design_candidates);
  const int max_candidates = wanted * config.max_candidates_per_pose;
  struct Feasible {
    int candidate;
    Equilibrium state;
  };
  std::vector<Feasible> feasible;
  for (int tried = 0; static_cast<int>(feasible.size()) < wanted; ++tried) {
    if (tried == max_candidates) {
      return Unexpected{"only " + std::to_string(feasible.size()) + " of " + std::to_string(wanted) +
                        " poses have a taut equilibrium after " + std::to_string(tried) + " candidates"};
    }
    const Waypoint w = waypoints.next();
    const EquilibriumResult state = solve_equilibrium(data.true_robot, w.position_world, w.yaw_rad, options);
    if (!state || !taut_enough(*state, spec.min_tension_n)) {
      ++data.skipped_candidates;
      continue;
    }
    feasible.push_back({w.candidate, *state});
  }
  if (config.design_candidates > 0) {
    std::vector<Pose> poses;
    for (const Feasible& f : feasible) poses.push_back(f.state.world_T_platform);
    std::vector<int> chosen = choose_informative_poses(data.nominal, poses, config.pose_count);
    std::sort(chosen.begin(), chosen.end());  // sample order = sequence order, as without a design
    std::vector<Feasible> measured;
    for (int k : chosen) measured.push_back(std::move(feasible[k]));
    feasible = std::move(measured);
  }
  for (const Feasible& f : feasible) {
    Rng noise = Rng::stream(config.seed, kStreamSensorNoise, static_cast<std::uint64_t>(f.candidate));
    data.samples.push_back(
        measure(data.true_robot, f.state, config.noise_scale, noise, static_cast<int>(data.samples.size())));
    data.states.push_back(f.state);
  }
  for (std::size_t k = 0; k < config.extra_positions.size(); ++k) {
    const Eigen::Vector3d& position = config.extra_positions[k];
    const EquilibriumResult state = solve_equilibrium(data.true_robot, position, 0.0, options);
    if (!state || !taut_enough(*state, spec.min_tension_n)) {
      return Unexpected{"extra position " + std::to_string(k + 1) + " (" + std::to_string(position.x()) + ", " +
                        std::to_string(position.y()) + ", " + std::to_string(position.z()) +
                        ") has no taut equilibrium: " + (state ? std::string("a cable below the tension floor") : state.error().message)};
    }
    Rng noise = Rng::stream(config.seed, kStreamExtraPoseNoise, static_cast<std::uint64_t>(k));
    data.samples.push_back(measure(data.true_robot, *state, config.noise_scale, noise, static_cast<int>(data.samples.size())));
    data.states.push_back(*state);
  }
  // After the noise, so a seed's noise is the same with and without a drift.
  const std::array<double, kCableCount>& drift = data.true_robot.effects.encoder_drift_m;
  const double last = static_cast<double>(std::max<std::size_t>(1, data.samples.size() - 1));
  for (std::size_t k = 0; k < data.samples.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) data.samples[k].encoder_m[i] += drift[i] * static_cast<double>(k) / last;
  }
  data.truth.outliers = plant_gross_errors(config.gross_errors, config.seed, data.nominal.reference_cable, data.samples);
  return data;
}

}  // namespace cdpr::sim
