#include "sim/discriminating_poses.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "sim/equilibrium.h"
#include "sim/rng.h"
#include "sim/sensors.h"

namespace cdpr::sim {
namespace {

// (arc length - chord) / chord of any cable at a candidate, at most: the
// daemon planner's default.
constexpr double max_sag_excess = 0.02;

// A member's noiseless readings at a rest, or none where it has no taut rest.
std::optional<Sample> predicted_readings(const TrueRobot& robot, const Eigen::Vector3d& position, double yaw_rad,
                                         double min_tension_n, double max_tension_n) {
  const EquilibriumResult state = solve_equilibrium(robot, position, yaw_rad, SolverOptions{});
  if (!state) return std::nullopt;
  for (int i = 0; i < kCableCount; ++i) {
    const CableEquilibrium& cable = state->cables[i];
    if (!(cable.tension_n >= min_tension_n && cable.tension_n <= max_tension_n)) return std::nullopt;
    // A cable hanging in a deep loop: a small anchor error moves such a rest
    // far (the planner's max_sag_excess, src/calibration/waypoint_planner.h).
    const double chord = (robot.robot.winches[i].anchor_world - cable.attachment_world).norm();
    if (cable.arc_length_m > (1.0 + max_sag_excess) * chord) return std::nullopt;
  }
  Rng unused = Rng::stream(0, 0);
  return measure(robot, *state, 0.0, unused, 0);
}

// sqrt(sum of squared reading differences in sigmas) of two predictions.
double distance_sigma(const Sample& a, const Sample& b, const NoiseSigmas& noise) {
  double sum = 0.0;
  for (int i = 0; i < kCableCount; ++i) sum += std::pow((a.encoder_m[i] - b.encoder_m[i]) / noise.encoder_m, 2);
  sum += std::pow((a.force_n - b.force_n) / noise.force_n, 2);
  const Eigen::AngleAxisd turn(a.world_R_platform.conjugate() * b.world_R_platform);
  sum += std::pow(turn.angle() / noise.orientation_rad, 2);
  return std::sqrt(sum);
}

// The smallest pairwise distance of the members' predictions at a rest, or
// none where a member has no taut rest.
std::optional<double> separation(const std::vector<TrueRobot>& members, const Eigen::Vector3d& position,
                                 double yaw_rad, const NoiseSigmas& noise, double min_tension_n,
                                 double max_tension_n) {
  std::vector<Sample> predicted;
  for (const TrueRobot& member : members) {
    std::optional<Sample> readings = predicted_readings(member, position, yaw_rad, min_tension_n, max_tension_n);
    if (!readings) return std::nullopt;
    predicted.push_back(*readings);
  }
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < predicted.size(); ++a) {
    for (std::size_t b = a + 1; b < predicted.size(); ++b) {
      smallest = std::min(smallest, distance_sigma(predicted[a], predicted[b], noise));
    }
  }
  return smallest;
}

double yaw_of(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d r = q.toRotationMatrix();
  return std::atan2(r(1, 0), r(0, 0));
}

}  // namespace

DiscriminatingPoses discriminating_poses(const Robot& robot, const NoiseSigmas& noise,
                                         const std::vector<Sample>& measured, const MimicSet& set,
                                         const DiscriminationOptions& options) {
  DiscriminatingPoses out;
  // Every member on the geometry of the first (the term the diagnosis
  // took): the anchors each fit found differ by their own noise, which the
  // next fit re-estimates from every pose anyway; what a pose must show is
  // the terms' difference.
  std::vector<TrueRobot> members;
  const Calibration* geometry = nullptr;
  for (const MimicMember& member : set.members) {
    if (member.fit.winches.empty()) continue;
    if (!geometry) geometry = &member.fit;
    Calibration fit = member.fit;
    fit.winches = geometry->winches;
    members.push_back(robot_of(robot, fit));
  }
  if (members.size() < 2) {
    out.message = "fewer than two members of the mimic set have a fit to predict with";
    return out;
  }
  if (measured.empty()) {
    out.message = "no poses measured: no box to choose from";
    return out;
  }
  Eigen::Vector3d low = measured.front().position_world, high = low;
  for (const Sample& s : measured) {
    low = low.cwiseMin(s.position_world);
    high = high.cwiseMax(s.position_world);
    const std::optional<double> d = separation(members, s.position_world, yaw_of(s.world_R_platform), noise, 0.0,
                                               std::numeric_limits<double>::infinity());
    if (d) out.measured_separation_sigma = std::max(out.measured_separation_sigma, *d);
  }

  if (options.workspace_min && options.workspace_max) {
    low = *options.workspace_min;
    high = *options.workspace_max;
  }
  struct Candidate {
    Eigen::Vector3d position;
    double separation;
  };
  std::vector<Candidate> feasible;
  const Eigen::Vector3d step = (high - low).cwiseQuotient(
      Eigen::Vector3d(std::max(1, options.grid_xy - 1), std::max(1, options.grid_xy - 1), std::max(1, options.grid_z - 1)));
  for (int ix = 0; ix < options.grid_xy; ++ix) {
    for (int iy = 0; iy < options.grid_xy; ++iy) {
      for (int iz = 0; iz < options.grid_z; ++iz) {
        const Eigen::Vector3d p = low + step.cwiseProduct(Eigen::Vector3d(ix, iy, iz));
        ++out.candidates;
        const std::optional<double> d =
            separation(members, p, 0.0, noise, options.min_tension_n, options.max_tension_n);
        if (d) feasible.push_back({p, *d});
      }
    }
  }
  out.feasible = static_cast<int>(feasible.size());
  if (feasible.empty()) {
    out.message = "no candidate in the box has a rest within the tension limits for every member";
    return out;
  }
  std::stable_sort(feasible.begin(), feasible.end(),
                   [](const Candidate& a, const Candidate& b) { return a.separation > b.separation; });
  const double spacing = options.min_spacing_fraction * (high - low).norm();
  for (const Candidate& c : feasible) {
    if (static_cast<int>(out.waypoints.size()) == options.count) break;
    const bool apart = std::all_of(out.waypoints.begin(), out.waypoints.end(), [&](const formats::PlannedWaypoint& w) {
      return (w.position_world - c.position).norm() >= spacing;
    });
    if (apart) out.waypoints.push_back({c.position, c.separation});
  }
  return out;
}

}  // namespace cdpr::sim
