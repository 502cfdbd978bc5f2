#pragma once
// Decides when the platform has come to rest at a waypoint, and averages the
// rest window into one sample row (samples.csv, docs/FORMATS.md).
//
// Time is the pose source's own time stamp (hal::PoseSample::source_time_us),
// not the daemon's clock: rates are the platform's, whatever the delay or
// time scale between the localization system and the daemon (a simulated
// robot running 20x faster than real time shows its poses 20x closer in
// time, but the source's stamps still say how fast the platform moves).
//
// The window is the last `window_us`, extended back to hold at least
// `min_samples` observations (when poses arrive sparsely in source time).
// Settled means, over the window:
//  - the window is covered (oldest observation at least window_us older than
//    the newest) by at least `min_samples` observations;
//  - the load cell's own stable bit is set in every observation;
//  - the tension's standard deviation is below `max_tension_std_n`;
//  - the platform's speed and angular rate are below their limits. Rates of
//    raw consecutive poses are noise divided by the sample interval (5 mm at
//    50 Hz reads as 0.25 m/s), so the window is cut into kRateBins bins of
//    equal duration and the rate is the largest change of the bin means
//    between neighbouring bins over the time between their centres. A platform
//    still moving or swinging slowly shows up there; white noise is averaged
//    down by the samples per bin, and what is left of it is taken off: each
//    change counts only by what exceeds kNoiseAllowance times its own
//    standard error (the noise from successive differences of the
//    observations), so a noisy pose source at a low rate does not read as
//    motion.
// One observation under a threshold is never enough (docs/STYLE.md).
//
// average_sigmas() gives the row's own noise (solver/model/sample.h
// SampleSigmas): each reading's standard error of the window mean
// (window_statistics.h) with robot.toml's per-reading sigma as the floor.
//
// Memory: a fixed-capacity ring and scratch allocated at construction; add(),
// check(), average() and average_sigmas() never allocate. When more than `capacity` observations fall in
// the window the oldest are dropped and the window can never be covered:
// size capacity >= window_us x sample rate (+ margin).
// Time is passed in with each observation ([us], the source's stamp); time
// going backwards resets the window.
// Not thread-safe.

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hal/clock.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr::calibration {

struct EquilibriumThresholds {
  hal::TimeUs window_us = 2'000'000;      // rest window [us]
  // Observations in the window, >= kRateBins. 100 is what the 2 s window
  // holds at the daemon's 50 Hz loop, so a source that delivers fewer poses
  // per second of its own time (a slower localization system, a
  // time-scaled simulation) still averages as many readings into a row.
  int min_samples = 100;
  double max_speed_mps = 0.002;           // platform speed [m/s]
  double max_angular_rate_radps = 0.002;  // platform angular rate [rad/s]
  double max_tension_std_n = 10.0;        // tension standard deviation [N]
};

struct EquilibriumObservation {
  hal::TimeUs time_us = 0;  // the pose source's stamp [us]
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();              // [m]
  Eigen::Quaterniond world_R_platform = Eigen::Quaterniond::Identity();  // unit
  std::array<double, kCableCount> encoder_m{};                           // [m]
  double tension_n = 0.0;                                                // [N]
  bool tension_stable = false;                                           // load cell stable bit
};

enum class EquilibriumVerdict {
  kNotEnoughData,   // window not covered yet or too few observations
  kTensionUnstable, // a load-cell stable bit is clear
  kTensionSpread,   // tension standard deviation too large
  kMoving,          // speed too large
  kRotating,        // angular rate too large
  kSettled,
};

const char* to_string(EquilibriumVerdict verdict);

// The verdict and the measured values behind it (for the status line).
struct EquilibriumCheck {
  EquilibriumVerdict verdict = EquilibriumVerdict::kNotEnoughData;
  int samples = 0;
  hal::TimeUs span_us = 0;           // newest - oldest observation time
  double speed_mps = 0.0;            // measured as described above, noise allowance taken off
  double angular_rate_radps = 0.0;
  double tension_std_n = 0.0;
  bool settled() const { return verdict == EquilibriumVerdict::kSettled; }
};

class EquilibriumDetector {
 public:
  static constexpr int kRateBins = 4;
  // Standard errors of a bin-mean change that count as noise, not motion:
  // pure noise exceeds 2 standard errors of a 3-D change (chi-square with 3
  // degrees of freedom above 12) with probability 0.007.
  static constexpr double kNoiseAllowance = 2.0;

  // capacity >= 2: the most observations kept (see above).
  EquilibriumDetector(const EquilibriumThresholds& thresholds, std::size_t capacity);

  // Forgets every observation (e.g. when a new waypoint starts).
  void reset();
  void add(const EquilibriumObservation& observation);
  EquilibriumCheck check() const;
  // Mean of the window: position, sign-aligned normalized quaternion mean,
  // encoders and tension. Precondition: at least one observation.
  Sample average() const;
  // The standard errors of average()'s readings, with `per_reading` as the
  // floor of each reading's scatter. The pose's are the RMS over the three
  // axes (position, and rotation relative to the mean orientation).
  // Precondition: at least one observation.
  SampleSigmas average_sigmas(const NoiseSigmas& per_reading) const;

  int size() const { return static_cast<int>(count_); }
  const EquilibriumThresholds& thresholds() const { return thresholds_; }

 private:
  const EquilibriumObservation& at(std::size_t k) const;  // k = 0: oldest
  Eigen::Quaterniond mean_orientation() const;

  EquilibriumThresholds thresholds_;
  std::vector<EquilibriumObservation> ring_;
  mutable std::vector<double> scratch_;  // one reading's series, for average_sigmas()
  std::size_t first_ = 0;
  std::size_t count_ = 0;
};

}  // namespace cdpr::calibration
