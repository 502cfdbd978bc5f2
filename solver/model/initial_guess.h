#pragma once
// Starting values for a calibration, from the nominal anchors and the data
// alone (no variable is ever set from ground truth).

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "solver/model/platform_statics.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr {

// Paper Eq. (17)-(18): f_v0 = m g / 4 and f_h0 = f_v0 / tan(alpha), alpha
// being the elevation of the reference cable's chord seen from its anchor.
Eigen::Vector2d paper_reference_force_guess(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Sample& sample);

// Fallback when Eq. (17)-(18) leaves the statics unusable: the least-squares
// tensions of four straight cables along their chords carrying the weight,
// split into the reference cable's horizontal and vertical parts.
Eigen::Vector2d rigid_reference_force_guess(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Sample& sample);

// Last resort when both guesses leave a cable pushing: the best point of a
// grid over (f_h, f_v) at which every cable pulls, by the height and force
// residuals. Empty when no such point exists (the nominal geometry cannot
// hold the measured pose).
std::optional<Eigen::Vector2d> search_feasible_reference_force(const Robot& robot,
                                                               const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                               const Sample& sample, double sigma_height_m);

// `sample` with its pose turned by `yaw_rad` about the world vertical
// through the platform origin (the start's heading search).
Sample turned_about_vertical(const Sample& sample, double yaw_rad);

// The statics at `sample`'s pose with the anchors held fixed, factorised
// once for any reference force (ReferenceForceMap, platform_statics.h).
// Empty where they are undefined (a vertical cable, a singular Eq. (11)).
std::optional<ReferenceForceMap> sample_force_map(const Robot& robot,
                                                  const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                  const Sample& sample);

// Refines (f_h, f_v) of the reference cable at one pose, anchors held fixed,
// by the small damped solver (solver/nls/dense_damped_solver.h) on the
// height (Eq. 15) and force (Eq. 16) residuals, starting from `guess`. Empty when the statics cannot be
// evaluated near the guess (e.g. a cable would push).
std::optional<Eigen::Vector2d> refine_reference_force(const Robot& robot,
                                                      const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                      const Sample& sample, const Eigen::Vector2d& guess,
                                                      double sigma_height_m);
// The same from the pose's statics already factorised: `map` is
// sample_force_map(robot, anchors, sample).
std::optional<Eigen::Vector2d> refine_reference_force(const Robot& robot, const ReferenceForceMap& map,
                                                      const Sample& sample, const Eigen::Vector2d& guess,
                                                      double sigma_height_m);

// Refines the reference force and the heading together (anchors held
// fixed): the same damped solve over (f_h, f_v, yaw), yaw a turn of
// the measured pose about the world vertical through the platform origin,
// kept in [yaw_min_rad, yaw_max_rad], starting from `guess` at
// `yaw_guess_rad`. Every accepted point is evaluable (all cables pull).
// Empty when the statics cannot be evaluated at the start.
// `map_at_guess`: the statics at the guess's heading, sample_force_map() of
// turned_about_vertical(sample, yaw_guess_rad) (the caller has them from
// refining the guess).
struct ForceAndHeading {
  Eigen::Vector2d reference_force = Eigen::Vector2d::Zero();
  double yaw_rad = 0.0;
};
std::optional<ForceAndHeading> refine_reference_force_and_heading(
    const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors, const Sample& sample,
    const Eigen::Vector2d& guess, double yaw_guess_rad, double yaw_min_rad, double yaw_max_rad, double sigma_height_m,
    const ReferenceForceMap& map_at_guess);

// Encoder offsets as the mean of (reading - modelled length) over the
// samples; `lengths[k][i]` is the modelled length of cable i at sample k.
std::array<double, kCableCount> mean_offsets(const std::vector<Sample>& samples,
                                             const std::vector<std::array<double, kCableCount>>& lengths);

}  // namespace cdpr
