#pragma once
// Where to rest the platform next so that the data tell apart the members
// of a mimic set (solver/diagnosis/diagnosis.h): model terms that explain
// the poses measured so far about equally well.
//
// Each member's fit says what the robot is (its term values, on the anchors
// and offsets of the first member's fit, sim/true_robot.h robot_of: the
// anchors the fits found differ by their noise, which the next fit
// re-estimates from every pose; a pose must show the terms' difference).
// At a pose it has not seen, each
// predicts the readings the true physics gives for that robot (noiseless
// sim/sensors.h measure at the sim/equilibrium.h rest). Where two members'
// predictions differ by many noise sigmas, one measurement there favours
// one of them; where they agree, no number of measurements can. A pose's
// separation is the smallest, over the pairs of members, of the distance
// between their predicted readings in sigmas (encoders, load cell,
// orientation; the position is where the platform is held):
//
//   separation(p) = min_{a<b} sqrt( sum_r ((reading_a,r(p) - reading_b,r(p)) / sigma_r)^2 )
//
// The candidates are a grid over the workspace given, or else over the box
// of the poses already measured (where the robot has been is where it may
// go), kept when every member has a rest there with every cable's tension
// within the limits. The waypoints are the candidates of largest
// separation, each at least a spacing from those taken before, so that
// they are not the same pose measured again. A separation a re-fit of the
// anchors and offsets could absorb still counts here: the figure ranks the
// poses, the diagnosis after them is the test.
// Pure numerics on the simulator's physics, no I/O.

#include <optional>
#include <string>
#include <vector>

#include "solver/diagnosis/diagnosis.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "src/formats/waypoints_csv.h"

namespace cdpr::sim {

struct DiscriminationOptions {
  int count = 8;                   // waypoints wanted
  int grid_xy = 9;                 // candidates per horizontal axis of the box
  int grid_z = 5;                  // candidates along z
  double min_spacing_fraction = 0.15;  // of the box diagonal, between two waypoints
  double min_tension_n = 20.0;     // every cable at every member's rest [N]
  double max_tension_n = 3000.0;   // the daemon's [waypoints] default [N]
  // The box of the candidates (platform origin, world); both or neither.
  // Default: the box of the poses measured.
  std::optional<Eigen::Vector3d> workspace_min, workspace_max;
};

struct DiscriminatingPoses {
  std::vector<formats::PlannedWaypoint> waypoints;  // largest separation first
  int candidates = 0;           // on the grid
  int feasible = 0;             // with a taut rest for every member
  double measured_separation_sigma = 0.0;  // the largest over the poses measured
  std::string message;          // why there are none, when empty
};

// `noise` are the sigmas the diagnosis weighed the readings with (robot.toml's,
// scaled by its noise findings). Members without a fit (none) are skipped;
// fewer than two with one: no waypoints, message says why.
DiscriminatingPoses discriminating_poses(const Robot& robot, const NoiseSigmas& noise,
                                         const std::vector<Sample>& measured, const MimicSet& set,
                                         const DiscriminationOptions& options);

}  // namespace cdpr::sim
