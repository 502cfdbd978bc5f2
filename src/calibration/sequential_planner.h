#pragma once
// Sequential, information-driven waypoints: measure until the anchors and
// encoder offsets are known to a stated accuracy, in as little robot time as
// the candidates allow (docs/calibration.md "Sequential waypoints").
//
// 1. Start with the fewest spread waypoints (farthest-point order over the
//    feasible candidates) whose straight-cable Fisher information on the
//    nominal anchors has full rank: the problem is identifiable. At least
//    `min_count` of them when the caller needs that many rows anyway.
// 2. After each sample, re-solve (calibrate() on every row so far, started
//    from the last estimate) and take its covariance of anchors and offsets.
//    A failed re-solve does not end the run: the next waypoint is then the
//    next unused candidate in spread order (status().fell_back).
//    Given where the candidates came from (CandidateSource), they are planned
//    again from the estimate once its anchors or offsets have moved by more
//    than their target sigma from those the candidates were planned with:
//    the workspace box, each rest pose and the tension and sag limits then
//    follow the robot as measured, not the nominal anchors. With nominal
//    anchors metres off on a small robot, candidates planned from them sit
//    where the true robot has no rest (a skip costs a move and a settle) and
//    miss the edge of the true workspace, where the informative poses are.
// 3. Stop when every anchor axis sigma <= target_anchor_sigma_m and every
//    offset sigma <= target_offset_sigma_m (kTargetReached), at max_count
//    samples (kMaxCount), or when no candidate is left (kNoCandidates).
// 4. Otherwise go to the candidate with the largest expected gain per unit
//    of robot time. Gain: the relative progress of every variance towards
//    a quarter of its target variance that the pose would make,
//        sum_j log(max(P_jj, t_j^2 / 4) / max(S_jj, t_j^2 / 4)),   S = (P^-1 + I_k)^-1,
//    P the fit's covariance, I_k the pose's information at the current
//    estimate (solver/calibration/pose_design.h) scaled to the rows' own
//    noise.
//    Time: travel from the current waypoint at the winch speed
//    (waypoint_tour.h) plus the expected settle time, plus a horizon
//    (SequentialOptions::score_horizon_s).
// 5. The samples (and robot time) still needed are forecast by running
//    step 4 ahead on the expected information until the largest sigma over
//    its target is expected to reach 1, the expected progress discounted by
//    how much of it the re-solves have realised so far (the straight-cable
//    information is optimistic), at most up to max_count.
//
// The candidates' gains are scored with fixed-size matrices: no allocation
// in the per-candidate loop. Pure logic: no I/O, no clock.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/calibration/pose_design.h"
#include "src/calibration/equilibrium_detector.h"
#include "src/calibration/waypoint_planner.h"
#include "src/calibration/waypoint_tour.h"

namespace cdpr::calibration {

struct SequentialOptions {
  double target_anchor_sigma_m = 0.02;  // every anchor axis 1-sigma [m]
  // Every encoder offset 1-sigma [m]. An offset error moves the modelled
  // platform along its cable by as much, like an anchor error along the
  // cable: the same budget as an anchor axis.
  double target_offset_sigma_m = 0.02;
  int min_count = 0;                    // samples before stopping, at least
  int max_count = 35;                   // samples, at most
  double winch_speed_mps = 2.0;         // profile speed of the winches [m/s]
  // Expected wait for the sample after a move, per waypoint [s]: the
  // detector's (equilibrium_detector.h; its defaults: the 40 s sway window).
  double settle_s = expected_settle_s(EquilibriumThresholds{});
  // The score divides a candidate's gain by its move and settle time plus
  // this [s]. The gain per second of the next move alone is myopic: it
  // prefers short hops that gain little, each of which still costs a settle
  // and leaves the informative poses as far away as before. With the
  // horizon, time decides between candidates of similar gain (fewer
  // waypoints, less robot time in the replay: docs/calibration.md).
  // 0: the plain gain per second.
  double score_horizon_s = 30.0;
  CalibrationOptions solver;            // of each re-solve
  // The re-solve: calibrate() when empty. Tests put a failing one here to
  // drive the fallback.
  std::function<CalibrationResult(const Robot&, const std::vector<Sample>&, const CalibrationOptions&)> resolve;
};

enum class StopReason { kNotStopped, kTargetReached, kMaxCount, kNoCandidates };
const char* to_string(StopReason reason);

// Where the sequential run stands, for status displays.
struct SequentialStatus {
  int samples = 0;
  bool solved = false;                  // the last re-solve succeeded
  double largest_anchor_sigma_m = 0.0;  // of the last successful re-solve
  double largest_offset_sigma_m = 0.0;
  // Largest sigma over its target (anchor axes and offsets); <= 1 reached.
  double largest_sigma_ratio = 0.0;
  // Samples still needed and the modelled robot time [s] they take (move
  // and settle): the forecast of step 5, or before the first re-solve the
  // rest of the initial set (a lower bound: estimated_time_left_s < 0 when
  // nothing is known).
  int estimated_samples_left = 0;
  double estimated_time_left_s = 0.0;
  // The next waypoint is the spread order's, the last re-solve having failed.
  bool fell_back = false;
  int replans = 0;  // times the candidates were planned again from the estimate
  StopReason stop = StopReason::kNotStopped;
};

// The grid and limits the candidates were planned with, and the encoder
// offsets of their payout targets: to plan them again from the estimate.
struct CandidateSource {
  PlannerOptions options;
  std::array<double, kCableCount> payout_offset_m{};
};

class SequentialPlanner {
 public:
  // `candidates`: feasible waypoints (candidate_waypoints()); `start`: where
  // the platform is. The nominal robot's noise weighs the information.
  // Without `source` the candidates stay as given.
  SequentialPlanner(const Robot& nominal, std::vector<Waypoint> candidates, const Pose& start,
                    const SequentialOptions& options, std::optional<CandidateSource> source = std::nullopt);

  // Index into candidates() of the waypoint to measure next; empty when the
  // run is over (status().stop says why). The same answer until
  // add_sample() or skip() moves on; either may plan the candidates again,
  // so indices and references into candidates() last until then.
  std::optional<int> next() const { return next_; }
  // The sample measured at candidate `index` (re-solves once the initial
  // waypoints are done).
  void add_sample(int index, const Sample& sample);
  // Candidate `index` could not be measured (not reached, no rest): never offered again.
  void skip(int index);

  const std::vector<Waypoint>& candidates() const { return candidates_; }
  const std::vector<Sample>& samples() const { return samples_; }
  // The identifiable spread set, as indices into the first candidates.
  const std::vector<int>& initial() const { return initial_; }
  // The last successful re-solve (ok() false before the first).
  const CalibrationResult& last_fit() const { return fit_; }
  SequentialStatus status() const { return status_; }
  // Modelled robot time [s] of the moves and settles so far.
  double modelled_time_s() const { return modelled_time_s_; }

 private:
  using Vector = Eigen::Matrix<double, kDesignParameters, 1>;
  struct Choice {
    int index = -1;
    DesignInformation posterior;
    Vector after;  // diagonal of the posterior covariance
  };

  void moved_on();
  // The rest of the initial set's modelled time, in status_.
  void estimate_initial_left();
  void resolve();
  void replan();
  void decide();
  void forecast(const DesignInformation& prior);
  Robot design_robot() const;
  DesignInformation prior_information(const Robot& design) const;
  std::optional<Choice> choose(const Robot& design, const DesignInformation& prior, const std::vector<bool>& taken,
                               const Pose& from) const;
  double move_time_s(const Pose& from, int index) const;
  // Largest variance over its target variance (anchor axes and offsets).
  double ratio_sq(const Vector& variance) const;

  Robot nominal_;
  std::vector<Waypoint> candidates_;
  SequentialOptions options_;
  std::optional<CandidateSource> source_;
  std::vector<int> initial_;     // the identifiable spread set, in tour order
  std::size_t initial_done_ = 0;
  std::vector<bool> used_;       // measured or skipped
  std::vector<int> spread_;      // spread order over the candidates: the fallback
  std::vector<Eigen::Vector3d> visited_;  // candidates measured or skipped
  std::vector<Sample> samples_;
  std::size_t resolved_samples_ = 0;      // samples in the last re-solve
  Pose at_;                      // the platform's (planned) pose now
  CalibrationResult fit_;
  Robot estimate_;               // nominal with the last fit's anchors: the warm start
  std::array<double, kCableCount> estimate_offset_m_{};
  std::array<Eigen::Vector3d, kCableCount> planned_anchors_;  // the candidates' anchors
  std::array<double, kCableCount> planned_offset_m_{};         // and offsets
  std::optional<int> next_;
  double modelled_time_s_ = 0.0;
  // Progress of the largest sigma ratio (log of its square) the re-solves
  // realised and the information predicted, summed over the steps so far.
  double realised_progress_ = 0.0, predicted_progress_ = 0.0;
  std::optional<double> predicted_ratio_sq_;  // of the chosen waypoint
  double ratio_sq_before_ = 0.0;              // at the choice
  SequentialStatus status_;
};

}  // namespace cdpr::calibration
