#include "solver/calibrate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "solver/cable_prediction.h"
#include "solver/effect_pose_factor.h"
#include "solver/factor_parameters.h"
#include "solver/initial_guess.h"
#include "solver/pose_prior_factor.h"
#include "solver/rigid_encoder_factor.h"
#include "solver/static_pose_factor.h"

namespace cdpr {
namespace {

using Anchors = std::array<Eigen::Vector3d, kCableCount>;

Pose measured_pose(const Sample& s) { return {s.position_world, s.world_R_platform}; }

std::string check_inputs(const Robot& robot, const std::vector<Sample>& samples) {
  if (robot.cable_count() != kCableCount) {
    return "the solver needs exactly " + std::to_string(kCableCount) + " cables, robot has " +
           std::to_string(robot.cable_count());
  }
  if (robot.reference_cable < 0 || robot.reference_cable >= kCableCount) return "reference cable index out of range";
  if (samples.size() < 3) return "need at least 3 samples, got " + std::to_string(samples.size());
  return {};
}

std::string check_effects(const CalibrationOptions& options) {
  if (!options.effects.empty() && options.cable_model != CableModelKind::kCatenary) {
    return "model terms (effects) need the catenary cable model";
  }
  return effect_set_conflict(options.effects);
}

// Data-driven start for one pose: the paper's force guess refined with the
// anchors held at their nominal values; falls back to the bare guess.
struct PoseStart {
  bool usable = false;
  Pose world_T_platform;  // the measured pose, turned about the vertical if the statics needed it
  Eigen::Vector2d reference_force = Eigen::Vector2d::Zero();
  std::array<double, kCableCount> lengths{};
};

// The cables' lines of action pass close to the platform centre, so its
// yaw balance is weak: with anchors metres off, the measured heading may
// admit no tension-only equilibrium. The paper (Sec. IV-C) lets a rotation
// variable absorb this; here the start turns the pose about the vertical by
// the smallest angle at which a force guess refines to a plausible
// equilibrium (every cable pulling, the reference tension within a few times
// the larger of the platform's weight and the load cell's reading, no cable
// much longer than its chord: near the edge of the feasible headings the
// refinement can run off to absurd forces or sags); then force and heading
// are refined together within a degree of that turn. The pose prior pulls the heading back as the anchors converge.
PoseStart start_pose(const Robot& robot, const Anchors& anchors, const Sample& sample, const CalibrationOptions& o) {
  constexpr double kYawStepRad = 0.25 * M_PI / 180.0;
  constexpr int kYawSteps = 120;  // up to +-30 degrees
  constexpr double kMaxTensionRatio = 4.0;
  constexpr double kPolishRad = 1.0 * M_PI / 180.0;
  constexpr double kMaxArcOverChord = 1.5;
  const double max_tension =
      kMaxTensionRatio * std::max(robot.platform_mass_kg * robot.gravity_mps2, sample.force_n);
  PoseStart start;
  auto take = [&](const Sample& turned, const Eigen::Vector2d& force) {
    const Pose pose = measured_pose(turned);
    const auto cables = predict_cables(robot, anchors, pose, force);
    if (!cables) return false;
    // The height fit alone also admits a cable hanging in a deep U whose
    // lowest point is the attachment; no real pose looks like that.
    for (int i = 0; i < kCableCount; ++i) {
      const double chord = (pose.transform(robot.winches[i].attachment_platform) - anchors[i]).norm();
      if (!((*cables)[i].arc_length_m <= kMaxArcOverChord * chord)) return false;
    }
    start.usable = true;
    start.world_T_platform = pose;
    start.reference_force = force;
    for (int i = 0; i < kCableCount; ++i) start.lengths[i] = (*cables)[i].arc_length_m;
    return true;
  };
  for (int step = 0; step <= 2 * kYawSteps; ++step) {
    const double yaw = kYawStepRad * ((step + 1) / 2) * (step % 2 ? 1.0 : -1.0);
    Sample turned = sample;
    turned.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())) * sample.world_R_platform;
    for (int guess = 0; guess < 2; ++guess) {
      const Eigen::Vector2d initial = guess == 0 ? paper_reference_force_guess(robot, anchors, turned)
                                                 : rigid_reference_force_guess(robot, anchors, turned);
      const std::optional<Eigen::Vector2d> force =
          refine_reference_force(robot, anchors, turned, initial, o.height_sigma_m);
      if (!force || !(force->norm() <= max_tension)) continue;
      const std::optional<ForceAndHeading> polished = refine_reference_force_and_heading(
          robot, anchors, sample, *force, yaw, yaw - kPolishRad, yaw + kPolishRad, o.height_sigma_m);
      if (polished && polished->reference_force.norm() <= max_tension) {
        Sample polished_turn = sample;
        polished_turn.world_R_platform =
            Eigen::Quaterniond(Eigen::AngleAxisd(polished->yaw_rad, Eigen::Vector3d::UnitZ())) * sample.world_R_platform;
        if (take(polished_turn, polished->reference_force)) return start;
      }
      if (take(turned, *force)) return start;
    }
  }
  // Neither guess leads to a plausible equilibrium at any heading: search
  // the forces at the measured heading as a last resort.
  const std::optional<Eigen::Vector2d> feasible = search_feasible_reference_force(robot, anchors, sample, o.height_sigma_m);
  const std::optional<Eigen::Vector2d> force =
      feasible ? refine_reference_force(robot, anchors, sample, *feasible, o.height_sigma_m) : std::nullopt;
  if (force) take(sample, *force);
  return start;
}

std::array<double, kCableCount> straight_lengths(const Robot& robot, const Anchors& anchors, const Sample& sample) {
  std::array<double, kCableCount> lengths{};
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d b = sample.world_R_platform * robot.winches[i].attachment_platform + sample.position_world;
    lengths[i] = (b - anchors[i]).norm();
  }
  return lengths;
}

// Unweighted residual statistics at the solution, with plain least squares.
void fill_fit_rms(const Robot& robot, const std::vector<Sample>& samples, const Problem& problem,
                  const CalibrationOptions& options, FitSummary& fit) {
  Anchors anchors;
  for (int i = 0; i < kCableCount; ++i) anchors[i] = problem.vector(AnchorKey(i));
  double sum_encoder = 0.0, sum_force = 0.0;
  int n_encoder = 0, n_force = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Key pose_key = PoseKey(static_cast<int>(k));
    const Pose pose = problem.pose(pose_key);
    if (!options.effects.empty()) {
      // The model terms change lengths and readings: ask the factor's own model.
      const EffectPoseFactor factor(robot, static_cast<int>(k), samples[k], options.height_sigma_m, Loss{},
                                    options.effects);
      PosePrediction prediction;
      if (!factor.predict(parameter_blocks(problem, factor).data(), prediction)) continue;
      for (int i = 0; i < kCableCount; ++i) sum_encoder += std::pow(prediction.encoder_residual_m[i], 2);
      n_encoder += kCableCount;
      sum_force += std::pow(prediction.force_residual_n, 2);
      ++n_force;
    } else if (options.cable_model == CableModelKind::kCatenary) {
      const Eigen::Vector2d force = problem.vector(ReferenceForceKey(static_cast<int>(k)));
      const auto cables = predict_cables(robot, anchors, pose, force);
      if (!cables) continue;
      for (int i = 0; i < kCableCount; ++i) {
        const double r = (*cables)[i].arc_length_m + problem.vector(OffsetKey(i))(0) - samples[k].encoder_m[i];
        sum_encoder += r * r;
        ++n_encoder;
      }
      const double rf = (*cables)[robot.reference_cable].tension_n - samples[k].force_n;
      sum_force += rf * rf;
      ++n_force;
    } else {
      for (int i = 0; i < kCableCount; ++i) {
        const Eigen::Vector3d b = pose.transform(robot.winches[i].attachment_platform);
        const double r = (b - anchors[i]).norm() + problem.vector(OffsetKey(i))(0) - samples[k].encoder_m[i];
        sum_encoder += r * r;
        ++n_encoder;
      }
    }
  }
  fit.rms_encoder_m = n_encoder ? std::sqrt(sum_encoder / n_encoder) : 0.0;
  fit.rms_force_n = n_force ? std::sqrt(sum_force / n_force) : 0.0;
}

}  // namespace

BuiltProblem build_calibration_problem(const Robot& robot, const std::vector<Sample>& all_samples,
                                       const CalibrationOptions& options) {
  BuiltProblem built;
  std::string why = check_inputs(robot, all_samples);
  if (why.empty()) why = check_effects(options);
  if (!why.empty()) {
    built.message = why;
    return built;
  }
  Anchors nominal;
  for (int i = 0; i < kCableCount; ++i) nominal[i] = robot.winches[i].anchor_world;
  const Loss loss{options.huber_width};
  const bool catenary = options.cable_model == CableModelKind::kCatenary;

  // Set-up: a start for every pose; poses the model cannot start from are
  // refused by id, never dropped silently.
  std::vector<Sample>& samples = built.samples;
  std::vector<Eigen::Vector2d> forces;
  std::vector<Pose> start_poses;
  std::vector<std::array<double, kCableCount>> lengths;
  for (const Sample& sample : all_samples) {
    if (catenary) {
      const PoseStart start = start_pose(robot, nominal, sample, options);
      if (!start.usable) {
        built.rejected_samples.push_back(sample.id);
        continue;
      }
      forces.push_back(start.reference_force);
      start_poses.push_back(start.world_T_platform);
      lengths.push_back(start.lengths);
    } else {
      lengths.push_back(straight_lengths(robot, nominal, sample));
      start_poses.push_back(measured_pose(sample));
    }
    samples.push_back(sample);
  }
  if (samples.size() < 3) {
    built.message = "too few usable samples: " + std::to_string(samples.size()) + " of " +
                    std::to_string(all_samples.size()) + " can be started from the nominal anchors";
    return built;
  }
  const std::array<double, kCableCount> offsets = mean_offsets(samples, lengths);

  built.problem = std::make_unique<Problem>();
  Problem& problem = *built.problem;
  for (int i = 0; i < kCableCount; ++i) {
    problem.add_vector(AnchorKey(i), nominal[i]);
    problem.add_vector(OffsetKey(i), Eigen::Matrix<double, 1, 1>(offsets[i]));
  }
  for (Effect e : options.effects) problem.add_vector(EffectKey(e), Eigen::VectorXd::Zero(effect_dimension(e)));
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const int pose_index = static_cast<int>(k);
    problem.add_pose(PoseKey(pose_index), start_poses[k]);
    problem.add_factor(std::make_unique<PosePriorFactor>(pose_index, measured_pose(samples[k]),
                                                         robot.noise.position_m, robot.noise.orientation_rad, loss));
    if (catenary) {
      problem.add_vector(ReferenceForceKey(pose_index), forces[k]);
      if (options.effects.empty()) {
        problem.add_factor(
            std::make_unique<StaticPoseFactor>(robot, pose_index, samples[k], options.height_sigma_m, loss));
      } else {
        problem.add_factor(std::make_unique<EffectPoseFactor>(robot, pose_index, samples[k], options.height_sigma_m,
                                                              loss, options.effects));
      }
    } else {
      for (int i = 0; i < kCableCount; ++i) {
        problem.add_factor(std::make_unique<RigidEncoderFactor>(
            pose_index, i, robot.winches[i].attachment_platform, samples[k].encoder_m[i], robot.noise.encoder_m, loss));
      }
    }
  }
  return built;
}

namespace {

CalibrationResult calibrate_once(const Robot& robot, const std::vector<Sample>& all_samples,
                                 const CalibrationOptions& options) {
  CalibrationResult result;
  BuiltProblem built = build_calibration_problem(robot, all_samples, options);
  result.rejected_samples = built.rejected_samples;
  if (!built.problem) {
    result.message = built.message;
    return result;
  }
  const std::vector<Sample>& samples = built.samples;
  Problem& problem = *built.problem;
  const bool catenary = options.cable_model == CableModelKind::kCatenary;

  SolverOptions solver_options;
  solver_options.max_iterations = options.max_iterations;
  solver_options.progress = options.progress;
  LevenbergMarquardt lm(problem, solver_options);
  result.solver = lm.solve();
  result.message = result.solver.message;
  if (!result.solver.usable()) return result;

  std::vector<Key> globals;
  for (int i = 0; i < kCableCount; ++i) {
    globals.push_back(AnchorKey(i));
    globals.push_back(OffsetKey(i));
  }
  for (Effect e : options.effects) globals.push_back(EffectKey(e));
  const Eigen::MatrixXd covariance = lm.covariance(globals);
  result.global_keys = globals;
  result.global_covariance = covariance;

  Calibration& cal = result.calibration;
  cal.model = {catenary ? "catenary" : "rigid"};
  for (int base = 4 * kCableCount; Effect e : options.effects) {
    FittedEffect fitted{e, {}, {}};
    const Eigen::VectorXd value = problem.vector(EffectKey(e));
    for (int j = 0; j < effect_dimension(e); ++j) {
      fitted.value.push_back(value(j));
      fitted.sigma.push_back(covariance.size() > 0 ? std::sqrt(covariance(base + j, base + j)) : 0.0);
    }
    base += effect_dimension(e);
    cal.model.emplace_back(effect_model_name(e));
    add_effect_values(e, fitted.value, fitted.sigma, cal.effects);
    result.effects.push_back(std::move(fitted));
  }
  cal.samples = static_cast<int>(samples.size());
  cal.winches.resize(kCableCount);
  for (int i = 0; i < kCableCount; ++i) {
    WinchCalibration& w = cal.winches[i];
    w.anchor_world = problem.vector(AnchorKey(i));
    w.offset_m = problem.vector(OffsetKey(i))(0);
    if (covariance.size() > 0) {
      const int base = 4 * i;  // anchor (3) then offset (1) per cable, in `globals` order
      for (int a = 0; a < 3; ++a) w.anchor_sigma(a) = std::sqrt(covariance(base + a, base + a));
      w.offset_sigma_m = std::sqrt(covariance(base + 3, base + 3));
    }
  }
  cal.fit.cost_initial = result.solver.initial_cost;
  cal.fit.cost_final = result.solver.final_cost;
  cal.fit.iterations = result.solver.iterations;
  fill_fit_rms(robot, samples, problem, options, cal.fit);
  result.ok = covariance.size() > 0;
  if (!result.ok) result.message += "; the fit's information matrix is singular: parameters not observable";
  return result;
}

}  // namespace

CalibrationResult calibrate(const Robot& robot, const std::vector<Sample>& samples, const CalibrationOptions& options) {
  CalibrationResult first = calibrate_once(robot, samples, options);
  if (first.ok || options.cable_model != CableModelKind::kCatenary) return first;
  // A tight Eq. (15) makes the cost landscape narrow; far from the solution
  // LM can stall where the anchors are unobservable. Continuation: solve with
  // a ten times looser height consistency from the nominal anchors, then
  // with the requested one from there.
  CalibrationOptions loose = options;
  loose.height_sigma_m *= 10.0;
  const CalibrationResult coarse = calibrate_once(robot, samples, loose);
  if (coarse.calibration.winches.empty()) return first;
  Robot restart = robot;
  for (int i = 0; i < kCableCount; ++i) restart.winches[i].anchor_world = coarse.calibration.winches[i].anchor_world;
  CalibrationResult second = calibrate_once(restart, samples, options);
  if (!second.ok) return first;
  second.message += " (after a restart with a looser height consistency: the first solve stopped where the anchors "
                    "were unobservable)";
  return second;
}

}  // namespace cdpr
