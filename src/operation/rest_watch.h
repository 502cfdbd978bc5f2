#pragma once
// Finds the rests of a platform that the robot's own controller moves
// (watch mode, docs/operation.md): every new pose with the
// payouts and the tension of the same step goes into the calibration's
// equilibrium detector (src/calibration/equilibrium_detector.h, its
// thresholds and window as configured); the first settled verdict after a
// motion is one rest, whose window average is a sample row with its own
// sigmas, as a calibration run takes it, once the verdict has stayed
// settled for two rest windows more (source time): a platform still
// creeping towards its rest under the rate thresholds would otherwise give
// a window whose pose and encoders disagree by millimetres, many sigmas of
// the health test. Then nothing more until the
// platform moves again (a verdict of motion, kMoving or kRotating): a
// long rest is one rest, not one per step.
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

  int rests() const { return rests_; }
  // The detector's last verdict and figures, for the status.
  const calibration::EquilibriumCheck& last_check() const { return check_; }
  // A rest was reported and the platform has not moved since.
  bool resting() const { return !armed_; }

 private:
  calibration::EquilibriumDetector detector_;
  NoiseSigmas noise_;
  calibration::EquilibriumCheck check_;
  hal::TimeUs last_pose_us_ = -1;  // source stamp of the last pose added
  bool armed_ = true;              // the next settled verdict is a new rest
  hal::TimeUs settled_since_us_ = -1;  // source time the verdict turned settled; -1: not settled
  int rests_ = 0;
};

}  // namespace cdpr::operation
