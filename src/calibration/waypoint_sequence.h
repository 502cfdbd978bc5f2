#pragma once
// The waypoints of one daemon run, whichever strategy picks them
// (docs/calibration.md "Sequential waypoints and robot time"): a fixed plan
// ("spread", "informative": plan_waypoints(), driven as a tour) or the
// sequential planner, which chooses each next waypoint after re-solving
// with the samples so far and stops when the sigmas reach their targets.
// The state machine asks for the current waypoint and reports what became
// of it; this class keeps the plan's bookkeeping, the estimate of the robot
// time still needed, and the largest sigmas for status displays.
//
// A failed re-solve of the sequential planner (too few rows yet, the fit
// not converging) does not end the run: the next waypoint is then the next
// unused one in spread order, and remark() says so for the run log.
//
// Time left: the remaining waypoints' modelled time (move at the winch
// speed plus the expected settle, as the sequential planner models it; for
// the sequential strategy its forecast of the waypoints still needed from
// the expected information, discounted by the progress the re-solves have
// shown; before its first re-solve, the rest of its initial set: a lower
// bound) scaled by how the robot time spent so far compared with the
// model. The run's own clock measures, so the estimate follows the robot
// (or a virtual robot's time scale).
// Pure logic: no I/O; times are passed in.

#include <optional>
#include <string>
#include <vector>

#include "hal/clock.h"
#include "src/calibration/sequential_planner.h"
#include "src/calibration/waypoint_planner.h"

namespace cdpr::calibration {

enum class WaypointStrategy { kSpread, kInformative, kSequential };
const char* to_string(WaypointStrategy strategy);

class WaypointSequence {
 public:
  // Plans the run from `start_world` with `robot`'s anchors and the encoder
  // offsets `offset_m`. Returns what is wrong (no feasible plan), else "".
  std::string start(const Robot& robot, const std::array<double, kCableCount>& offset_m,
                    const Eigen::Vector3d& start_world, const PlannerOptions& planner, WaypointStrategy strategy,
                    const SequentialOptions& sequential, hal::TimeUs now_us);

  // A run through exactly `positions_world`, in that order
  // (given_waypoints(): all pass the planner's checks or the run has none).
  // strategy_name() is then "given". Returns what is wrong, else "".
  std::string start_given(const Robot& robot, const std::array<double, kCableCount>& offset_m,
                          const Eigen::Vector3d& start_world, const PlannerOptions& planner,
                          const std::vector<Eigen::Vector3d>& positions_world, const SequentialOptions& sequential,
                          hal::TimeUs now_us);

  // The waypoint to drive to next; null when the run's waypoints are done.
  const Waypoint* current() const;
  // The current waypoint was sampled / could not be (no rest, skipped).
  void sampled(const Sample& sample, hal::TimeUs now_us);
  void skipped(hal::TimeUs now_us);

  WaypointStrategy strategy() const { return strategy_; }
  // For status and the run log: the strategy's name, or "given".
  const char* strategy_name() const { return given_ ? "given" : to_string(strategy_); }
  // Waypoints planned: the fixed plan's size, or the sequential maximum.
  int planned() const;
  // Waypoints sampled or skipped so far.
  int visited() const { return visited_; }
  // Waypoints the run is expected to visit in all: the fixed plan's size,
  // or those visited plus the sequential planner's forecast.
  int expected_count() const;
  // Why the waypoints ended: "plan done", or the sequential planner's stop
  // reason ("target reached", "max count", "no candidates left").
  std::string stop_reason() const;
  // What the last sampled()/skipped() did that the log should say (a
  // fallback after a failed re-solve); empty otherwise.
  const std::string& remark() const { return remark_; }

  // Largest anchor-axis and offset 1-sigma [m] of the last successful
  // re-solve (sequential only).
  std::optional<double> largest_anchor_sigma_m() const;
  std::optional<double> largest_offset_sigma_m() const;
  // Robot time [s] still needed for the waypoints, estimated at the last
  // sampled()/skipped() (or the start); and when that was.
  double time_left_s() const { return time_left_s_; }
  hal::TimeUs estimated_at_us() const { return estimated_at_us_; }

  // The fixed plan (travel order), or the first candidates (sequential: the
  // planner may plan them again from its estimate).
  const WaypointPlan& plan() const { return plan_; }

 private:
  // Bookkeeping after the current waypoint was sampled or skipped at `reached`.
  void visited(const Pose& reached, hal::TimeUs now_us);
  double modelled_s(const Pose& from, const Pose& to) const;
  double modelled_left_s() const;

  WaypointStrategy strategy_ = WaypointStrategy::kSpread;
  bool given_ = false;  // start_given(): a fixed plan of the positions given
  Robot robot_;
  SequentialOptions sequential_options_;
  WaypointPlan plan_;                          // fixed plan, or the candidates
  std::optional<SequentialPlanner> sequential_;
  int visited_ = 0;
  Pose start_pose_;
  Pose at_;                                    // where the platform was last sent
  double modelled_spent_s_ = 0.0;
  hal::TimeUs started_us_ = 0;
  double time_left_s_ = 0.0;
  hal::TimeUs estimated_at_us_ = 0;
  std::string remark_;
};

}  // namespace cdpr::calibration
