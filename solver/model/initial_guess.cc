#include "solver/model/initial_guess.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "solver/model/catenary.h"
#include "solver/model/platform_statics.h"
#include "solver/nls/dense_damped_solver.h"

namespace cdpr {

Eigen::Vector2d paper_reference_force_guess(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Sample& sample) {
  const int ref = robot.reference_cable;
  const Eigen::Vector3d attachment_world =
      sample.world_R_platform * robot.winches[ref].attachment_platform + sample.position_world;
  const Eigen::Vector3d chord = attachment_world - anchors[ref];
  const double horizontal = std::hypot(chord.x(), chord.y());
  const double f_v0 = robot.platform_mass_kg * robot.gravity_mps2 / 4.0;  // Eq. (17)
  // Eq. (18): cos(alpha) = s_c^T chord / |chord| = horizontal / |chord|.
  const double alpha = std::acos(std::min(1.0, horizontal / chord.norm()));
  return {f_v0 / std::tan(alpha), f_v0};
}

Eigen::Vector2d rigid_reference_force_guess(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Sample& sample) {
  Eigen::Matrix<double, 6, kCableCount> wrench_per_tension;
  Eigen::Matrix<double, 3, kCableCount> directions;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d lever = sample.world_R_platform * robot.winches[i].attachment_platform;
    directions.col(i) = (anchors[i] - (sample.position_world + lever)).normalized();
    wrench_per_tension.col(i) << directions.col(i), lever.cross(directions.col(i));
  }
  const double weight = robot.platform_mass_kg * robot.gravity_mps2;
  Eigen::Matrix<double, 6, 1> wrench;
  wrench << 0.0, 0.0, weight, (sample.world_R_platform * robot.center_of_mass_platform).cross(Eigen::Vector3d(0, 0, weight));
  const Eigen::Vector4d tensions = wrench_per_tension.colPivHouseholderQr().solve(wrench);
  const Eigen::Vector3d u = directions.col(robot.reference_cable);
  const double tension = std::max(tensions(robot.reference_cable), 0.25 * weight);
  return {tension * std::hypot(u.x(), u.y()), tension * u.z()};
}

namespace {

constexpr int kFitRows = kCableCount + 1;  // Eq. (15) per cable, Eq. (16)
using FitResiduals = Eigen::Matrix<double, kFitRows, 1>;
using FitJacobian = Eigen::Matrix<double, kFitRows, 2>;

// The height (Eq. 15) and force (Eq. 16) residuals of StaticPoseFactor at
// one pose, whitened, as functions of the reference force alone through the
// statics' affine map, and (when `jacobian`) their derivatives. False where
// a cable would push: outside the model.
bool height_and_force(const Robot& robot, const ReferenceForceMap& map, const Sample& sample,
                      const Eigen::Vector2d& force, double sigma_height_m, FitResiduals& residual,
                      FitJacobian* jacobian) {
  const double weight_per_length = robot.gravity_mps2 * robot.cable_linear_density_kgpm;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector2d f = map.offset[i] + map.gain[i] * force;
    if (!(f.x() > 0.0)) return false;
    const CatenaryOutput shape =
        evaluate_catenary({f.x(), f.y(), map.span[i], map.anchor_z[i], weight_per_length}, jacobian != nullptr);
    residual(i) = (map.attachment_z[i] - shape.end_height) / sigma_height_m;
    if (jacobian) {
      jacobian->row(i) =
          -(shape.d_end_height(0) * map.gain[i].row(0) + shape.d_end_height(1) * map.gain[i].row(1)) / sigma_height_m;
    }
  }
  const double tension = force.norm();
  const double sigma_force = reading_sigmas(robot, sample).force_n;
  residual(kCableCount) = (tension - sample.force_n) / sigma_force;
  if (jacobian) {
    jacobian->row(kCableCount).setZero();
    if (tension > 0.0) jacobian->row(kCableCount) = force.transpose() / (tension * sigma_force);
  }
  return true;
}

bool fill_force_map(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors, const Sample& sample,
                    ReferenceForceMap& map) {
  StaticsInput in;
  in.world_T_platform = Pose{sample.position_world, sample.world_R_platform};
  in.anchor_world = anchors;
  return reference_force_map(robot, in, map) == StaticsStatus::kOk;
}

// The statics at the last two headings the heading fit evaluated. A trial
// whose step stopped on a bound keeps the current heading, and one after a
// refused step may return to it: both reuse its factorisation. Headings
// match by their bits, so a reused map is the one the heading would give.
class TurnedForceMaps {
 public:
  TurnedForceMaps(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors, const Sample& sample,
                  double known_yaw_rad, const ReferenceForceMap& known)
      : robot_(robot), anchors_(anchors), sample_(sample) {
    Entry& entry = entries_[0];
    entry.yaw_bits = std::bit_cast<std::uint64_t>(known_yaw_rad);
    entry.filled = entry.defined = true;
    entry.map = known;
  }

  // The statics at `sample` turned by `yaw_rad`; null where undefined.
  const ReferenceForceMap* at(double yaw_rad) {
    const std::uint64_t key = std::bit_cast<std::uint64_t>(yaw_rad);
    int e = 0;
    while (e < kEntries && !(entries_[e].filled && entries_[e].yaw_bits == key)) ++e;
    if (e == kEntries) {
      e = 1 - last_used_;  // the entry not used last
      Entry& entry = entries_[e];
      entry.yaw_bits = key;
      entry.filled = true;
      entry.defined = fill_force_map(robot_, anchors_, turned_about_vertical(sample_, yaw_rad), entry.map);
    }
    last_used_ = e;
    return entries_[e].defined ? &entries_[e].map : nullptr;
  }

 private:
  static constexpr int kEntries = 2;
  struct Entry {
    std::uint64_t yaw_bits = 0;
    bool filled = false;
    bool defined = false;
    ReferenceForceMap map;
  };
  const Robot& robot_;
  const std::array<Eigen::Vector3d, kCableCount>& anchors_;
  const Sample& sample_;
  std::array<Entry, kEntries> entries_;
  int last_used_ = 0;
};

// The start's small fits (solver/nls/dense_damped_solver.h) on the
// whitened height and force rows. A start needs its forces and heading near
// their minimum, not at it: the calibration refines them with everything
// else, and with the anchors metres off Gauss-Newton converges only
// linearly here, so the stop is loose (a gain below 1e-7 of 1 + chi2; the
// calibration's result does not depend on the digits beyond it). The
// damping starts at 1e-3, never falls below 1e-9 and is given up above
// 1e12; at most 50 trials.
DenseDampedOptions start_fit_options() {
  DenseDampedOptions options;
  options.trust_region = {1e3, 1e9, 1e-12};
  options.max_trials = 50;
  options.gain_tolerance = 1e-7;
  options.gain_floor = 1.0;
  return options;
}

}  // namespace

Sample turned_about_vertical(const Sample& sample, double yaw_rad) {
  Sample turned = sample;
  turned.world_R_platform =
      Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())) * sample.world_R_platform;
  return turned;
}

std::optional<ReferenceForceMap> sample_force_map(const Robot& robot,
                                                  const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                  const Sample& sample) {
  std::optional<ReferenceForceMap> map(std::in_place);
  if (!fill_force_map(robot, anchors, sample, *map)) map.reset();
  return map;
}

std::optional<Eigen::Vector2d> refine_reference_force(const Robot& robot,
                                                      const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                      const Sample& sample, const Eigen::Vector2d& guess,
                                                      double sigma_height_m) {
  const std::optional<ReferenceForceMap> map = sample_force_map(robot, anchors, sample);
  if (!map) return std::nullopt;
  return refine_reference_force(robot, *map, sample, guess, sigma_height_m);
}

std::optional<Eigen::Vector2d> refine_reference_force(const Robot& robot, const ReferenceForceMap& map,
                                                      const Sample& sample, const Eigen::Vector2d& guess,
                                                      double sigma_height_m) {
  // Only the height and force rows constrain the force; encoder rows carry
  // the still unknown offsets. The pose and anchors are fixed, so the
  // statics are factorised once and each trial costs four catenaries.
  auto evaluate = [&](const Eigen::Vector2d& force, FitResiduals& residual, FitJacobian* jacobian) {
    return height_and_force(robot, map, sample, force, sigma_height_m, residual, jacobian);
  };
  Eigen::Vector2d force = guess;
  DenseDampedSolver<kFitRows, 2> solver(start_fit_options());
  if (solver.minimize(force, evaluate).stop == DenseDampedStop::kNotEvaluable) return std::nullopt;
  return force;
}

std::optional<Eigen::Vector2d> search_feasible_reference_force(const Robot& robot,
                                                               const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                               const Sample& sample, double sigma_height_m) {
  const std::optional<ReferenceForceMap> map = sample_force_map(robot, anchors, sample);
  if (!map) return std::nullopt;
  FitResiduals residual;
  // A suspended platform's cables each carry at most a few times its weight.
  const double weight = robot.platform_mass_kg * robot.gravity_mps2;
  constexpr int kSteps = 60;
  std::optional<Eigen::Vector2d> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int a = 1; a <= kSteps; ++a) {
    for (int b = 0; b <= kSteps; ++b) {
      const Eigen::Vector2d force(4.0 * weight * a / kSteps, weight * (-1.0 + 3.0 * b / kSteps));
      if (!height_and_force(robot, *map, sample, force, sigma_height_m, residual, nullptr)) continue;
      const double cost = residual.squaredNorm();
      if (cost < best_cost) {
        best_cost = cost;
        best = force;
      }
    }
  }
  return best;
}

std::optional<ForceAndHeading> refine_reference_force_and_heading(
    const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors, const Sample& sample,
    const Eigen::Vector2d& guess, double yaw_guess_rad, double yaw_min_rad, double yaw_max_rad, double sigma_height_m,
    const ReferenceForceMap& map_at_guess) {
  using Jacobian3 = Eigen::Matrix<double, kFitRows, 3>;
  const double weight_per_length = robot.gravity_mps2 * robot.cable_linear_density_kgpm;
  const double sigma_force = reading_sigmas(robot, sample).force_n;
  TurnedForceMaps maps(robot, anchors, sample, yaw_guess_rad, map_at_guess);
  // Residuals and their Jacobian in (f_h, f_v, yaw) at one point: the
  // statics factorised at that heading, each catenary evaluated once.
  auto evaluate = [&](const Eigen::Vector2d& force, double yaw, FitResiduals& residual, Jacobian3& jacobian) {
    const ReferenceForceMap* map = maps.at(yaw);
    if (!map) return false;
    std::array<Eigen::Vector2d, kCableCount> f;
    for (int i = 0; i < kCableCount; ++i) {
      f[i] = map->offset[i] + map->gain[i] * force;
      if (!(f[i].x() > 0.0)) return false;
    }
    const std::array<Eigen::Vector2d, kCableCount> d_yaw = map->d_force_d_yaw(force);
    for (int i = 0; i < kCableCount; ++i) {
      const CatenaryOutput shape =
          evaluate_catenary({f[i].x(), f[i].y(), map->span[i], map->anchor_z[i], weight_per_length}, true);
      residual(i) = (map->attachment_z[i] - shape.end_height) / sigma_height_m;
      jacobian.block<1, 2>(i, 0) =
          -(shape.d_end_height(0) * map->gain[i].row(0) + shape.d_end_height(1) * map->gain[i].row(1)) / sigma_height_m;
      jacobian(i, 2) = -(shape.d_end_height(0) * d_yaw[i].x() + shape.d_end_height(1) * d_yaw[i].y() +
                         shape.d_end_height(2) * map->d_span_d_yaw[i]) /
                       sigma_height_m;
    }
    const double tension = force.norm();
    residual(kCableCount) = (tension - sample.force_n) / sigma_force;
    jacobian.row(kCableCount).setZero();
    if (tension > 0.0) jacobian.block<1, 2>(kCableCount, 0) = force.transpose() / (tension * sigma_force);
    return true;
  };
  // The unknowns as one vector (f_h, f_v, yaw), the heading within its
  // bounds: a step that would cross one stops the heading on it, and the
  // forces take the model's best step for that turn (clamping the heading
  // alone kept forces fitted to a far larger turn).
  auto evaluate_at = [&](const Eigen::Vector3d& x, FitResiduals& residual, Jacobian3* jacobian) {
    return evaluate(x.head<2>(), x(2), residual, *jacobian);
  };
  Eigen::Vector3d x(guess.x(), guess.y(), std::clamp(yaw_guess_rad, yaw_min_rad, yaw_max_rad));
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  DenseDampedSolver<kFitRows, 3> solver(start_fit_options());
  solver.set_bounds({-kInfinity, -kInfinity, yaw_min_rad}, {kInfinity, kInfinity, yaw_max_rad});
  if (solver.minimize(x, evaluate_at).stop == DenseDampedStop::kNotEvaluable) return std::nullopt;
  return ForceAndHeading{x.head<2>(), x(2)};
}

std::array<double, kCableCount> mean_offsets(const std::vector<Sample>& samples,
                                             const std::vector<std::array<double, kCableCount>>& lengths) {
  std::array<double, kCableCount> offsets{};
  for (std::size_t k = 0; k < samples.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) offsets[i] += samples[k].encoder_m[i] - lengths[k][i];
  }
  for (double& offset : offsets) offset /= static_cast<double>(samples.size());
  return offsets;
}

}  // namespace cdpr
