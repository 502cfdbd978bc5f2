#pragma once
// Finds the rests of a platform that the robot's own controller moves
// (watch mode, docs/operation.md): every new pose with the
// payouts and the tension of the same step goes into the calibration's
// equilibrium detector (src/calibration/equilibrium_detector.h, its
// thresholds and window as configured); the first settled verdict after a
// motion is one rest, whose window average is a sample row with its own
// sigmas, as a calibration run takes it, once the verdict has stayed
// settled for two rest windows more (source time) and the window's mean
// position has not moved over that hold beyond the two means' noise
// (kMaxMoveChiSquare; else the hold starts over): a platform still
// creeping towards its rest passes the rate limits' noise allowance of a
// window of 20 poses at 5-10 mm/s, and its window mean is then 1-2 cm from
// where the encoders hold it, many sigmas of the health test. A verdict of
// motion (kMoving or kRotating) ends a hold. Then nothing more until the
// platform has moved: a verdict of motion with the window's mean beyond the
// noise from the last rest (the rate test flags a resting platform now and
// then; that is the same rest, not a second one). A long rest is one rest.
// Not seen: a sway whose period exceeds the return window, slow enough at
// a turning point to hold still over the hold (the detector's limits).
// A step without a valid pose, payout or tension starts the window over.
// Time: the pose source's stamps (the detector's), and the caller's clock
// for when a rest was seen. Memory: the detector's ring, fixed at
// construction. Not thread-safe.

#include <array>
#include <cstddef>
#include <optional>

#include "hal/clock.h"
#include "hal/load_cell.h"
#include "hal/pose_source.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "src/calibration/equilibrium_detector.h"

namespace cdpr::operation {

struct WatchedRest {
  int index = 0;           // 1-based count of rests seen since start
  hal::TimeUs seen_us = 0; // the caller's clock when it settled
  hal::TimeUs source_time_us = 0;  // the pose source's stamp of the window's newest pose
  Sample sample;           // the window's average, sigmas filled in
  calibration::EquilibriumVerdict verdict = calibration::EquilibriumVerdict::kSettled;
};

// One step's readings: what the devices said last (any may be missing).
struct WatchReadings {
  std::optional<hal::PoseSample> pose;
  std::array<std::optional<double>, kCableCount> payout_m{};
  std::optional<hal::TensionSample> tension;
};

class RestWatch {
 public:
  RestWatch(const calibration::EquilibriumThresholds& thresholds, std::size_t capacity, const NoiseSigmas& noise);

  // The readings of one step; a rest when the platform has just come to rest.
  std::optional<WatchedRest> step(const WatchReadings& readings, hal::TimeUs now_us);

  // Chi-square (3 degrees of freedom) of the move between two window means'
  // positions, in their sigmas, above which the platform moved: the
  // detector's noise allowance of 2 standard errors on each axis (a resting
  // platform exceeds it with probability 0.007).
  static constexpr double kMaxMoveChiSquare = 12.0;

  int rests() const { return rests_; }
  // The detector's last verdict and figures, for the status.
  const calibration::EquilibriumCheck& last_check() const { return check_; }
  // A rest was reported and the platform has not moved since.
  bool resting() const { return !armed_; }

 private:
  // The hold starts (again) at this source time, from the window's mean now.
  void begin_hold(hal::TimeUs time_us);
  // The window's mean position is farther than the noise from `position` (of sigma_m per axis).
  bool moved_beyond_noise(const Eigen::Vector3d& position, double sigma_m) const;

  calibration::EquilibriumDetector detector_;
  NoiseSigmas noise_;
  calibration::EquilibriumCheck check_;
  hal::TimeUs last_pose_us_ = -1;  // source stamp of the last pose added
  bool armed_ = true;              // the next settled verdict is a new rest
  hal::TimeUs settled_since_us_ = -1;  // source time the verdict turned settled; -1: not settled
  // The window mean's position and its sigma when the hold began.
  Eigen::Vector3d held_position_ = Eigen::Vector3d::Zero();
  double held_sigma_m_ = 0.0;
  // The last rest's position and sigma: a move is a departure from it.
  Eigen::Vector3d rest_position_ = Eigen::Vector3d::Zero();
  double rest_sigma_m_ = 0.0;
  int rests_ = 0;
};

}  // namespace cdpr::operation
