#pragma once
// Which static poses to calibrate on (experimental design). How well the
// anchors and encoder offsets are determined depends far more on where the
// poses are than on how many there are: a cable that is nearly vertical at
// every pose says little about its anchor's horizontal position. This picks,
// from feasible candidate poses, greedily one at a time, the one that makes
// the sum of the variances of anchors and offsets smallest (A-optimal design
// on the Fisher information; the mean anchor error is what users judge, and
// on the small robot A-optimal beat D-optimal (log det) 0.11 m to 0.16 m).
//
// The information is that of the straight-cable model (paper Eq. 12-13 with
// the sag left out): encoder reading = |anchor - attachment| + offset, noise
// robot.noise.encoder_m; each pose is measured with the pose prior's sigmas
// and is a nuisance, eliminated by its Schur complement. Sag changes the
// cable directions by a few degrees, which changes the ranking little; it is
// a design criterion, not the estimator.
// Pure numerics, no I/O.

#include <vector>

#include <Eigen/Core>

#include "solver/nls/pose.h"
#include "solver/model/robot.h"

namespace cdpr {

// Parameters of the design: 3 anchor coordinates per cable, then one offset per cable.
inline constexpr int kDesignParameters = 4 * kCableCount;
using DesignInformation = Eigen::Matrix<double, kDesignParameters, kDesignParameters>;

// Information one measured pose adds about anchors and offsets (pose eliminated).
DesignInformation pose_information(const Robot& robot, const Pose& pose);

// Information about anchors and offsets of a set of poses, plus the tiny
// ridge below (so its inverse is always defined).
DesignInformation design_information(const Robot& robot, const std::vector<Pose>& poses);

// Indices of `count` distinct candidates, in the order chosen: each the one
// that lowers the summed variance most. Fewer when there are fewer
// candidates. A tiny ridge keeps the first, rank-deficient steps defined.
std::vector<int> choose_informative_poses(const Robot& robot, const std::vector<Pose>& candidates, int count);

// Sum of the variances [m^2] of anchors and offsets that a set of poses
// allows (Cramer-Rao, same ridge), to compare designs.
double design_variance_sum(const Robot& robot, const std::vector<Pose>& poses);

// Cramer-Rao covariance of anchors and offsets (straight cables, same ridge):
// the least any unbiased calibration from these poses can achieve with the
// encoders and pose tracker alone. Infinite diagonal when singular.
DesignInformation design_covariance(const Robot& robot, const std::vector<Pose>& poses);

}  // namespace cdpr
