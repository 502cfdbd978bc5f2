#pragma once
// Replays a waypoint strategy of the daemon offline on the simulator
// (docs/calibration.md "Sequential waypoints"): the platform is led to each
// planned waypoint (the true robot's rest pose at the planned position and
// heading), measured there, and the run is scored by its robot time and the
// final fit's accuracy.
//
// Robot-time model, per waypoint: the move, max_i |payout_i(to) -
// payout_i(from)| / winch speed (the winches run coordinated, the farthest
// at the profile speed; acceleration ignored), from the previous waypoint
// (the first from the start pose), plus `settle_s`: the wait for the
// sample, taken as the same for every waypoint (by default the daemon's
// sway window, expected_settle_s()). The solve time is
// not robot time. A waypoint where the true robot has no taut rest is
// skipped after its move and settle time.
//
// A sample is one reading of every sensor at the true rest with the
// preset's noise times `noise_scale`: the daemon averages a rest window into
// a row whose noise is a fraction of one reading's (docs/calibration.md
// "Honest sigmas"). Each row carries that noise as its own sigmas, and the
// nominal robot keeps the preset's per-reading noise, as robot.toml and the
// daemon's rows do. The default 0.11 is what those sigmas are on the virtual
// robot: a 2 s window of about 100 independent readings.
//
// The true rest is solved at the planned position and heading; where the
// simulator's solve fails there, within 0.03 rad of that heading (the
// heading is where the cables put the platform, not commanded).

#include <cstdint>
#include <string>
#include <vector>

#include "cdpr-accuracy/normalised_errors.h"
#include "sim/presets.h"
#include "solver/model/calibration.h"
#include "src/calibration/sequential_planner.h"
#include "src/calibration/waypoint_planner.h"

namespace cdpr::accuracy {

enum class Strategy { kSpread, kInformative, kSequential };

struct ReplayCase {
  sim::Preset preset = sim::Preset::kLarge;
  Strategy strategy = Strategy::kSequential;
  int count = 35;                       // waypoints of the fixed plans
  double anchor_perturbation_m = 0.3;   // nominal anchors off the truth by this [m]
  double noise_scale = 0.11;
  // Sequential: its candidate grid (0: the daemon's [waypoints] grid_xy, grid_z).
  int candidate_grid_xy = 0, candidate_grid_z = 0;
  calibration::SequentialOptions sequential;  // also the robot-time model (winch speed, settle)
  // Sequential: plan the candidates again from the estimate, as the daemon does.
  bool replan = true;
};

struct ReplayResult {
  std::uint64_t seed = 0;
  bool ok = false;              // the final fit succeeded
  // ...but did not pass the model-fit test or was under-determined: cdpr-calib
  // solve exits 3 and the daemon's validation refuses it (model_warning says why).
  bool misfit = false;
  std::string message;          // why the fit failed, or its model_warning
  double robot_time_s = 0.0;
  double travel_m = 0.0;        // summed winch travel
  double travel_nn_m = 0.0;     // fixed plans: the same waypoints by nearest neighbour alone
  int waypoints = 0;            // measured
  int skipped = 0;
  std::string stop;             // sequential: why it stopped
  // Sequential: the planner's forecast of the waypoints still to sample,
  // after each re-solve, against those it then sampled: mean |error| and
  // mean error (forecast - actual) over the re-solves.
  double forecast_abs_error = 0.0, forecast_bias = 0.0;
  double anchor_error_m = 0.0;        // mean over cables of |a - a_true|
  double worst_anchor_error_m = 0.0;  // largest over cables
  double offset_error_m = 0.0;        // mean over cables of |l0 - l0_true|
  double largest_anchor_sigma_m = 0.0, largest_offset_sigma_m = 0.0;  // final fit
  double normalised_sq_sum = 0.0;     // (error / sigma)^2 over anchor axes and offsets
  int normalised_count = 0;
  // The same errors against the final fit's full covariance.
  NormalisedErrors normalised;
  // The run's data set as cdpr-calib reads it, to fit it again or diagnose
  // it: the nominal robot, the rows measured, the truth.
  Robot nominal;
  std::vector<Sample> samples;
  Truth truth;
};

// The daemon's planner settings for the preset's robot (waypoint box, limits).
calibration::PlannerOptions replay_planner_options(sim::Preset preset);

ReplayResult replay(const ReplayCase& c, std::uint64_t seed);

}  // namespace cdpr::accuracy
