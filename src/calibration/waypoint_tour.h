#pragma once
// The order in which the platform visits a set of static poses: a short open
// tour from where it is (no return), so that the robot spends its time
// measuring rather than travelling.
//
// Cost of a move: the winches run coordinated, all arriving together and the
// one with the farthest to go at the profile speed, so a move takes
// max_i |chord_i(to) - chord_i(from)| / speed. The chords (anchor to
// attachment, straight) stand in for the payouts: they differ by the sag
// excess, at most a few per cent. The tour is built by nearest neighbour and
// then improved by 2-opt (reverse a stretch whenever that shortens the tour)
// until no reversal helps; the metric is symmetric, so reversing a stretch
// keeps its inner cost.
// Pure logic: no I/O, no clock.

#include <array>
#include <vector>

#include <Eigen/Core>

#include "solver/model/robot.h"
#include "solver/nls/pose.h"

namespace cdpr::calibration {

using AnchorPositions = std::array<Eigen::Vector3d, kCableCount>;

// Largest change of a cable's straight length [m] between two platform poses.
double winch_travel_m(const Robot& robot, const AnchorPositions& anchors, const Pose& from, const Pose& to);

// Visiting order of `stops` (indices, each once) from `start`: nearest
// neighbour, then 2-opt when `improve`.
std::vector<int> tour_order(const Robot& robot, const AnchorPositions& anchors, const Pose& start,
                            const std::vector<Pose>& stops, bool improve = true);

// Summed winch travel [m] of visiting `stops` in `order` from `start`.
double tour_travel_m(const Robot& robot, const AnchorPositions& anchors, const Pose& start,
                     const std::vector<Pose>& stops, const std::vector<int>& order);

}  // namespace cdpr::calibration
