#pragma once
// A whole simulated calibration data set: the three files of docs/FORMATS.md
// (robot.toml, samples.csv, truth.toml) as values, plus the true state at
// every sample for model checks (e.g. the paper's Table I).
//
// Reproducible: the same config gives identical data. Random parts draw from
// separate streams of the seed (sim/stream_purpose.h): true encoder offsets
// (uniform +-offset range of the preset), nominal anchor perturbation,
// waypoints, and each candidate waypoint's sensor noise, so two configs that
// differ only in effects or noise scale share waypoints and offsets.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sim/equilibrium.h"
#include "sim/outliers.h"
#include "sim/presets.h"
#include "sim/true_robot.h"
#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "src/formats/expected.h"

namespace cdpr::sim {

struct DatasetConfig {
  Preset preset = Preset::kLarge;
  int pose_count = 35;
  std::uint64_t seed = 1;
  // robot.toml's nominal anchors = true anchors + a random vector of this norm [m].
  double anchor_perturbation_m = 0.0;
  HiddenEffects effects;
  // Multiplies every sensor sigma; 0 = noiseless. robot.toml's [noise] gets
  // the scaled sigmas (the preset's when 0, since sigmas must be > 0).
  double noise_scale = 1.0;
  // The true orientation noise over the sigma robot.toml states (1: as
  // stated): a localisation noisier than its data sheet, for the noise
  // terms of cdpr-calib diagnose (docs/diagnosis.md).
  double orientation_noise_factor = 1.0;
  // Waypoint box (platform origin, world) instead of the preset's, e.g. the
  // wider spread a calibration plan uses for observability; both or neither.
  std::optional<Eigen::Vector3d> workspace_min, workspace_max;
  // Pose design. 0: the first pose_count feasible candidates of the waypoint
  // sequence (an even spread). N > 0: N feasible candidates, of which the
  // pose_count most informative about anchors and offsets are measured
  // (solver/calibration/pose_design.h, A-optimal, judged with the NOMINAL anchors as a
  // planner must).
  int design_candidates = 0;
  // Gross errors planted after the measurement (sim/outliers.h): a fraction
  // of the rows with one encoder reading off by 0.5-2 m, a fraction with the
  // load cell off by 50-500 N (either sign); listed in truth.toml.
  GrossErrors gross_errors;
  // Poses measured after the regular ones, at these positions of the
  // platform origin (yaw 0, as a planner holds it): e.g. the waypoints that
  // tell mimicking model terms apart (cdpr-calib diagnose). Each row draws
  // its noise from its own stream, so the regular rows are the same with and
  // without them. A position without a taut equilibrium is an error.
  std::vector<Eigen::Vector3d> extra_positions;
  int segments = 2000;                // sim/cable_shooting.h
  int max_candidates_per_pose = 20;   // give up after this many candidates per wanted pose
};

struct SimulatedDataset {
  Robot nominal;            // robot.toml
  TrueRobot true_robot;     // the simulated robot
  Truth truth;              // truth.toml
  std::vector<Sample> samples;        // samples.csv, ids 0..n-1
  std::vector<Equilibrium> states;    // true state of samples[k]
  int skipped_candidates = 0;         // waypoints without a taut equilibrium or below the tension floor
};

Expected<SimulatedDataset, std::string> simulate_dataset(const DatasetConfig& config);

// The robot simulate_dataset uses: the preset with the config's effects and
// random true offsets.
TrueRobot make_true_robot(const DatasetConfig& config);

}  // namespace cdpr::sim
