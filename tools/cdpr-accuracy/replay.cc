#include "cdpr-accuracy/replay.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "sim/dataset.h"
#include "sim/equilibrium.h"
#include "sim/rng.h"
#include "sim/sensors.h"
#include "sim/stream_purpose.h"
#include "src/calibration/waypoint_tour.h"

namespace cdpr::accuracy {
namespace {

using calibration::Waypoint;

// The true robot led to waypoint `index`, its robot time and its sample.
class Rig {
 public:
  Rig(const sim::SimulatedDataset& data, const ReplayCase& c, std::uint64_t seed, const Pose& start)
      : data_(data), case_(c), seed_(seed), at_(start) {}

  // Moves to `waypoint` and measures; empty when the true robot has no rest there.
  std::optional<Sample> visit(int index, const Waypoint& waypoint) {
    const Pose& planned = waypoint.rest.world_T_platform;
    const Eigen::Matrix3d rotation = planned.world_R_platform.toRotationMatrix();
    const double yaw_rad = std::atan2(rotation(1, 0), rotation(0, 0));
    sim::EquilibriumResult state = sim::solve_equilibrium(data_.true_robot, planned.position_world, yaw_rad);
    // The heading is where the cables put the platform: when the simulator's
    // solve (from the level rigid statics) fails at exactly the planned one,
    // a rest a little off it counts.
    for (const double turn_rad : {0.01, -0.01, 0.03, -0.03}) {
      if (state) break;
      state = sim::solve_equilibrium(data_.true_robot, planned.position_world, yaw_rad + turn_rad);
    }
    // A true rest whose cable would sag to the floor is none: the planner
    // keeps the tensions up with the nominal anchors, the true anchors can
    // leave a cable nearly slack, and the simulator then solves its rest as
    // a catenary hundreds of metres long hanging far below the floor (a
    // payout no winch would make; the real cable would lie on the floor).
    if (state && !above_floor(*state)) state = sim::EquilibriumResult(Unexpected{sim::EquilibriumFailure{}});
    const Pose& reached = state ? state->world_T_platform : planned;
    const double travel_m =
        calibration::winch_travel_m(data_.true_robot.robot, nominal_anchors(data_.true_robot.robot), at_, reached);
    travel_m_ += travel_m;
    robot_time_s_ += travel_m / case_.sequential.winch_speed_mps + case_.sequential.settle_s;
    at_ = reached;
    if (!state) return std::nullopt;
    sim::Rng noise = sim::Rng::stream(seed_, sim::kStreamSensorNoise, static_cast<std::uint64_t>(index));
    Sample sample = sim::measure(data_.true_robot, *state, case_.noise_scale, noise, sample_id_++);
    const NoiseSigmas& reading = data_.nominal.noise;
    sample.sigma.encoder_m.fill(case_.noise_scale * reading.encoder_m);
    sample.sigma.force_n = case_.noise_scale * reading.force_n;
    sample.sigma.position_m = case_.noise_scale * reading.position_m;
    sample.sigma.orientation_rad = case_.noise_scale * reading.orientation_rad;
    return sample;
  }

  double robot_time_s() const { return robot_time_s_; }
  // Each cable's lowest point above the floor (z = 0). A cable that leaves
  // the attachment downwards (its vertical force on the platform v < 0)
  // sags below it by (tension - h) / weight per length.
  bool above_floor(const sim::Equilibrium& state) const {
    const double weight_npm = data_.true_robot.cable_weight_per_length_npm();
    return std::all_of(state.cables.begin(), state.cables.end(), [&](const sim::CableEquilibrium& cable) {
      const double sag_m = cable.v_n < 0.0 ? (cable.tension_n - cable.h_n) / weight_npm : 0.0;
      return cable.attachment_world.z() - sag_m > 0.0;
    });
  }
  double travel_m() const { return travel_m_; }

 private:
  const sim::SimulatedDataset& data_;
  const ReplayCase& case_;
  std::uint64_t seed_;
  Pose at_;
  int sample_id_ = 0;
  double robot_time_s_ = 0.0;
  double travel_m_ = 0.0;
};

void score(const sim::SimulatedDataset& data, const CalibrationResult& fit, ReplayResult& r) {
  r.ok = fit.ok;
  r.message = fit.message;
  if (!fit.ok) return;
  r.misfit = fit.misfit;
  if (fit.misfit) r.message = fit.calibration.model_warning;
  const int n = kCableCount;
  Eigen::VectorXd errors(4 * n), sigmas(4 * n);  // per cable: anchor axes, offset (global_covariance's order)
  for (int i = 0; i < n; ++i) {
    const WinchCalibration& w = fit.calibration.winches[i];
    const WinchTruth& truth = data.truth.winches[i];
    const Eigen::Vector3d error = w.anchor_world - truth.anchor_world;
    const double offset_error = w.offset_m - truth.offset_m;
    r.anchor_error_m += error.norm() / n;
    r.worst_anchor_error_m = std::max(r.worst_anchor_error_m, error.norm());
    r.offset_error_m += std::abs(offset_error) / n;
    r.largest_anchor_sigma_m = std::max(r.largest_anchor_sigma_m, w.anchor_sigma.maxCoeff());
    r.largest_offset_sigma_m = std::max(r.largest_offset_sigma_m, w.offset_sigma_m);
    r.normalised_sq_sum += error.cwiseQuotient(w.anchor_sigma).squaredNorm() + std::pow(offset_error / w.offset_sigma_m, 2);
    r.normalised_count += 4;
    errors.segment<3>(4 * i) = error;
    errors(4 * i + 3) = offset_error;
    sigmas.segment<3>(4 * i) = w.anchor_sigma;
    sigmas(4 * i + 3) = w.offset_sigma_m;
  }
  r.normalised = normalised_errors(errors, sigmas, fit.global_covariance);
}

}  // namespace

calibration::PlannerOptions replay_planner_options(sim::Preset preset) {
  // The daemon's [waypoints] defaults: PlannerOptions' own (the ConfigDefaults test holds them to the key table).
  calibration::PlannerOptions o;
  if (preset == sim::Preset::kSmall) {
    // 12.5 x 4.5 m footprint, anchors 28.5 m up, a 4.4 kg platform.
    o.margin_m = 1.0;
    o.z_min_m = 3.0;
    o.z_max_m = 18.0;
    o.min_tension_n = 2.0;
  }
  return o;
}

ReplayResult replay(const ReplayCase& c, std::uint64_t seed) {
  ReplayResult r;
  r.seed = seed;
  sim::DatasetConfig config;
  config.preset = c.preset;
  config.pose_count = 1;  // for the robots and the truth; the samples are measured here
  config.seed = seed;
  config.anchor_perturbation_m = c.anchor_perturbation_m;
  config.noise_scale = 1.0;  // robot.toml: one reading's noise; the rows carry their own (Rig::visit)
  const auto data = sim::simulate_dataset(config);
  if (!data) {
    r.message = "simulation failed: " + data.error();
    return r;
  }
  const Robot& nominal = data->nominal;
  calibration::PlannerOptions options = replay_planner_options(c.preset);
  options.waypoint_count = c.count;
  options.seed = static_cast<std::uint32_t>(seed);
  const std::array<double, kCableCount> no_offsets{};
  calibration::WaypointPlan candidates = calibration::candidate_waypoints(nominal, no_offsets, options);
  if (!candidates.ok() || candidates.waypoints.empty()) {
    r.message = "no candidates: " + candidates.problem;
    return r;
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Waypoint& w : candidates.waypoints) centre += w.rest.world_T_platform.position_world;
  centre /= static_cast<double>(candidates.waypoints.size());
  const Pose start{Eigen::Vector3d(centre.x(), centre.y(), options.z_min_m), Eigen::Quaterniond::Identity()};

  Rig rig(*data, c, seed, start);
  std::vector<Sample> samples;
  if (c.strategy == Strategy::kSequential) {
    calibration::PlannerOptions grid = options;
    if (c.candidate_grid_xy > 0) grid.grid_xy = c.candidate_grid_xy;
    if (c.candidate_grid_z > 0) grid.grid_z = c.candidate_grid_z;
    if (c.candidate_grid_xy > 0 || c.candidate_grid_z > 0) {
      candidates = calibration::candidate_waypoints(nominal, no_offsets, grid);
      if (!candidates.ok() || candidates.waypoints.empty()) {
        r.message = "no candidates: " + candidates.problem;
        return r;
      }
    }
    calibration::SequentialOptions sequential = c.sequential;
    sequential.solver = CalibrationOptions{};
    std::optional<calibration::CandidateSource> source;
    if (c.replan) source = calibration::CandidateSource{grid, no_offsets};
    calibration::SequentialPlanner planner(nominal, std::move(candidates.waypoints), start, sequential, source);
    std::vector<std::pair<int, int>> forecasts;  // (samples so far, forecast left) after each re-solve
    while (const std::optional<int> k = planner.next()) {
      if (std::optional<Sample> sample = rig.visit(*k, planner.candidates()[*k])) {
        planner.add_sample(*k, *sample);
        const calibration::SequentialStatus status = planner.status();
        if (status.solved && planner.next()) forecasts.emplace_back(status.samples, status.estimated_samples_left);
      } else {
        ++r.skipped;
        planner.skip(*k);
      }
    }
    samples = planner.samples();
    for (const auto& [so_far, left] : forecasts) {
      const double error = left - (static_cast<double>(samples.size()) - so_far);
      r.forecast_abs_error += std::abs(error) / forecasts.size();
      r.forecast_bias += error / forecasts.size();
    }
    r.stop = calibration::to_string(planner.status().stop);
  } else {
    options.selection = c.strategy == Strategy::kInformative ? calibration::WaypointSelection::kInformative
                                                             : calibration::WaypointSelection::kSpread;
    const calibration::WaypointPlan plan = calibration::plan_waypoints(nominal, no_offsets, start.position_world, options);
    if (!plan.ok()) {
      r.message = "no plan: " + plan.problem;
      return r;
    }
    std::vector<Pose> stops;
    for (const Waypoint& w : plan.waypoints) stops.push_back(w.rest.world_T_platform);
    const auto anchors = nominal_anchors(nominal);
    r.travel_nn_m = calibration::tour_travel_m(nominal, anchors, start, stops,
                                               calibration::tour_order(nominal, anchors, start, stops, false));
    for (std::size_t k = 0; k < plan.waypoints.size(); ++k) {
      // Noise stream by plan position: each plan's own draws.
      if (std::optional<Sample> sample = rig.visit(static_cast<int>(k), plan.waypoints[k])) {
        samples.push_back(*sample);
      } else {
        ++r.skipped;
      }
    }
  }
  r.robot_time_s = rig.robot_time_s();
  r.travel_m = rig.travel_m();
  r.waypoints = static_cast<int>(samples.size());
  r.nominal = nominal;
  r.truth = data->truth;
  r.samples = samples;
  score(*data, calibrate(nominal, samples, CalibrationOptions{}), r);
  return r;
}

}  // namespace cdpr::accuracy
