// build_calibration_problem() (calibrate.h): the factor graph of one
// calibration at its data-driven start.
#include "solver/calibration/calibrate.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "solver/calibration/effect_pose_factor.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/calibration/pose_prior_factor.h"
#include "solver/calibration/rigid_encoder_factor.h"
#include "solver/calibration/static_pose_factor.h"
#include "solver/model/cable_prediction.h"
#include "solver/model/initial_guess.h"

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
    const Sample turned = turned_about_vertical(sample, yaw);
    // The statics at this heading, factorised once for both guesses and
    // the polish's start.
    const std::optional<ReferenceForceMap> map = sample_force_map(robot, anchors, turned);
    if (!map) continue;
    for (int guess = 0; guess < 2; ++guess) {
      const Eigen::Vector2d initial = guess == 0 ? paper_reference_force_guess(robot, anchors, turned)
                                                 : rigid_reference_force_guess(robot, anchors, turned);
      const std::optional<Eigen::Vector2d> force = refine_reference_force(robot, *map, turned, initial, o.height_sigma_m);
      if (!force || !(force->norm() <= max_tension)) continue;
      const std::optional<ForceAndHeading> polished = refine_reference_force_and_heading(
          robot, anchors, sample, *force, yaw, yaw - kPolishRad, yaw + kPolishRad, o.height_sigma_m, *map);
      if (polished && polished->reference_force.norm() <= max_tension) {
        if (take(turned_about_vertical(sample, polished->yaw_rad), polished->reference_force)) return start;
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
  built.reading_loss = std::make_unique<LossFunction>(LossFunction{LossKind::kHuber, options.huber_width});
  const Loss loss{0.0, built.reading_loss.get()};
  const Loss prior_loss{options.huber_width};
  const bool catenary = options.cable_model == CableModelKind::kCatenary;

  // Set-up: a start for every pose; poses the model cannot start from are
  // refused by id, never dropped silently.
  std::vector<Sample>& samples = built.samples;
  std::vector<Eigen::Vector2d> forces;
  std::vector<Pose> start_poses;
  std::vector<std::array<double, kCableCount>> lengths;
  samples.reserve(all_samples.size());
  forces.reserve(all_samples.size());
  start_poses.reserve(all_samples.size());
  lengths.reserve(all_samples.size());
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

  built.reading_factor.reserve(samples.size());
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
    const SampleSigmas sigma = reading_sigmas(robot, samples[k]);
    problem.add_factor(std::make_unique<PosePriorFactor>(pose_index, measured_pose(samples[k]), sigma.position_m,
                                                         sigma.orientation_rad, prior_loss));
    built.reading_factor.push_back(static_cast<int>(problem.factors().size()));
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
            pose_index, i, robot.winches[i].attachment_platform, samples[k].encoder_m[i], sigma.encoder_m[i], loss));
      }
    }
  }
  return built;
}

}  // namespace cdpr
