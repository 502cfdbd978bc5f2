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
//    motion;
//  - the platform did not come back to where it is: the return window (the
//    last sway_window_us, at least twice the rest window's span) is covered
//    (kNotEnoughData before), and, cut into bins as long as the rate bins
//    but at most kMaxReturnBinS, no bin in it is farther from the rest
//    window's mean position than an earlier bin by more than
//    kNoiseAllowance standard errors of the two bin means (kSwaying
//    otherwise).
// The rates bound how fast the platform moves, not how far it is from its
// rest: a sway of period T and amplitude A is slow at its turning points,
// where it is A from rest, and over a window short against T the rate
// limits (and their noise allowance) pass it for A of centimetres. A
// platform approaching rest without overshoot is the farther from where it
// is now the further back one looks; a swaying one was near its turning
// point one period earlier and up to 2 A away in between. So the return
// test finds a sway of any period shorter than the return window once its
// amplitude is above the noise of a bin mean, and leaves a monotone
// approach to the rate limits. Its bins are short against the sway
// periods it is for (a bin as long as a period averages the sway away: the
// rate bins of a rest window of min_samples sparse poses can be 10 s). It
// needs no period and no fit, but it needs the history: a turning point
// seen for less than a period looks like a platform coming to rest, so a
// platform at rest settles once the return window is covered (with estimate_sway, the sway fit needs that window
// too, and a slow window is tried as a sway before it is covered). Only
// the position is tested: a sway moves the platform's origin with its
// rotation.
// One observation under a threshold is never enough (docs/STYLE.md).
//
// A platform on long cables sways after a move with a period of seconds and
// little damping; waiting until the sway is below the rate thresholds can
// take minutes. With estimate_sway, a window whose speed or angular rate is
// above its limit is tried as a sway about a rest state instead: over the
// last sway_window_us (at least min_samples observations), every coordinate
// (position, rotation relative to the mean orientation, encoders, tension)
// is fitted with
//   y(t) = rest + exp(-lambda t) (a cos(w t) + b sin(w t)),
// one decaying oscillation (w, lambda) shared by all coordinates, found by
// a grid search and refinement on bin means of the position. The window is
// a sway about rest (kSwayEstimated, settled()) when:
//  - w lies inside the searched range: at least kMinSwayPeriods periods in
//    the window, at least kMinSamplesPerPeriod observations per period;
//  - the oscillation is there: its F statistic against a constant is at
//    least kMinSwaySignificance on a position or rotation axis (a platform
//    at rest whose noise once reads as motion is no sway);
//  - every position, rotation and tension coordinate's residual variance is
//    at most max_sway_misfit times its noise variance, the noise from the
//    residuals' differences 1/20 period apart (which a smooth misfit, a
//    second mode or a drift of the rest hardly enters, while the residuals'
//    variance grows with them; readings held between sensor updates still
//    differ over that lag).
// The load cell's stable bit is not asked then: the cell clears it for the
// very sway being fitted, and the tension must fit the same oscillation.
// average() and average_sigmas() give the fitted rest state and its
// standard errors: the residuals' scatter (per-reading floor) times the
// rest parameter's least-squares factor, times the residuals' correlation
// (window_statistics.h). The fit is repeated at most every
// kSwayRefitObservations new observations.
// A sway of several modes with different periods does not fit one
// oscillation and is waited out as before. The rest's sigma does not count
// the uncertainty of w and lambda (over whole periods the rest is nearly
// uncorrelated with them).
//
// average_sigmas() gives the row's own noise (solver/model/sample.h
// SampleSigmas): each reading's standard error of the window mean
// (window_statistics.h) with robot.toml's per-reading sigma as the floor.
//
// Memory: a fixed-capacity ring and scratch allocated at construction; add(),
// check(), average() and average_sigmas() never allocate. When more than
// `capacity` observations fall in the window the oldest are dropped and the
// window can never be covered: size capacity >= the longer of window_us and
// sway_window_us x sample rate, and >= 2 min_samples (+ margin).
// Time is passed in with each observation ([us], the source's stamp); time
// going backwards resets the window.
// Not thread-safe.

#include <algorithm>
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
  bool estimate_sway = true;               // false: wait for rest (see above)
  hal::TimeUs sway_window_us = 40'000'000; // window of the sway fit [us, source time]
  double max_sway_misfit = 1.5;           // residual / noise variance of a sway fit
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
  kSwaying,         // slow in the rest window, but the platform came back to it (see above)
  kSettled,
  kSwayEstimated,   // not at rest, but a sway about a rest state that the fit estimates
};

const char* to_string(EquilibriumVerdict verdict);

// The return test's window at full rate (see above): the least a waypoint
// waits before any verdict settles, whatever the detector.
inline hal::TimeUs return_window_us(const EquilibriumThresholds& t) {
  return std::max(t.sway_window_us, 2 * t.window_us);
}

// The robot time [s] a waypoint is expected to wait before its sample, for
// planning: a move excites sway and nothing settles before the return
// window is covered, when the sway estimate takes its sample; waiting for
// rest is modelled by that window alone (optimistic for a platform that
// sways).
inline double expected_settle_s(const EquilibriumThresholds& t) {
  return 1e-6 * static_cast<double>(return_window_us(t));
}

// The verdict and the measured values behind it (for the status line).
struct EquilibriumCheck {
  EquilibriumVerdict verdict = EquilibriumVerdict::kNotEnoughData;
  int samples = 0;
  bool covered = false;              // the rest window: span, min_samples, every rate bin
  hal::TimeUs span_us = 0;           // newest - oldest observation time
  double speed_mps = 0.0;            // measured as described above, noise allowance taken off
  double angular_rate_radps = 0.0;
  double tension_std_n = 0.0;
  double return_m = 0.0;             // the return test's largest excess over the noise [m], 0 when none
  double sway_period_s = 0.0;        // of the last sway fit, 0 without one
  double sway_misfit = 0.0;          // its largest residual / noise variance
  bool settled() const {
    return verdict == EquilibriumVerdict::kSettled || verdict == EquilibriumVerdict::kSwayEstimated;
  }
};

class EquilibriumDetector {
 public:
  static constexpr int kRateBins = 4;
  // Standard errors of a bin-mean change that count as noise, not motion:
  // pure noise exceeds 2 standard errors of a 3-D change (chi-square with 3
  // degrees of freedom above 12) with probability 0.007.
  static constexpr double kNoiseAllowance = 2.0;
  static constexpr double kMinSwayPeriods = 1.5;
  static constexpr int kMinSamplesPerPeriod = 10;
  static constexpr int kSwayRefitObservations = 25;
  // Least F statistic of the oscillation against a constant (largest over
  // the position and rotation axes): noise alone, even at the best of the
  // searched periods, stays far below.
  static constexpr double kMinSwaySignificance = 100.0;
  static constexpr int kSwayBins = 200;  // bin means of the grid search (and the return test)
  // Longest bin of the return test [s, source time]: a fifth of the
  // shortest sway period it is meant for (5 s).
  static constexpr double kMaxReturnBinS = 1.0;

  // capacity >= 2: the most observations kept (see above).
  EquilibriumDetector(const EquilibriumThresholds& thresholds, std::size_t capacity);

  // Forgets every observation (e.g. when a new waypoint starts).
  void reset();
  void add(const EquilibriumObservation& observation);
  EquilibriumCheck check() const;
  // Mean of the window: position, sign-aligned normalized quaternion mean,
  // encoders and tension; the fitted rest state when the last check() was
  // kSwayEstimated. Precondition: at least one observation.
  Sample average() const;
  // The standard errors of average()'s readings, with `per_reading` as the
  // floor of each reading's scatter. The pose's are the RMS over the three
  // axes (position, and rotation relative to the mean orientation).
  // Precondition: at least one observation.
  SampleSigmas average_sigmas(const NoiseSigmas& per_reading) const;

  // Observations in the rest window (the ring may hold the sway window too).
  int size() const { return static_cast<int>(count_ - window_begin()); }
  const EquilibriumThresholds& thresholds() const { return thresholds_; }

 private:
  // The fit of one coordinate set: rest values and their standard-error
  // factors (see above), valid for the newest observation it was made at.
  static constexpr int kSwayCoordinates = 7 + kCableCount;  // position 3, rotation 3, encoders, tension
  struct SwayFit {
    bool accepted = false;
    hal::TimeUs newest_us = -1;
    std::size_t added_at = 0;
    double omega_radps = 0.0, decay_per_s = 0.0;
    double misfit = 0.0;
    Eigen::Quaterniond mean_q = Eigen::Quaterniond::Identity();
    std::array<double, kSwayCoordinates> rest{}, scatter{}, factor{};
  };

  const EquilibriumObservation& at(std::size_t k) const;  // k = 0: oldest
  // The oldest observation of the rest window (the last window_us, at least
  // min_samples); the ring holds the longer sway window before it.
  std::size_t window_begin() const;
  Eigen::Quaterniond mean_orientation(std::size_t begin) const;
  double coordinate(const EquilibriumObservation& o, int c, const Eigen::Quaterniond& mean_q) const;
  // Fits the sway window (see above) into sway_, unless fitted recently.
  void fit_sway() const;
  double sway_residual_sum(double omega, double decay) const;
  // The return test (see above) of the rest window starting at rest_begin,
  // with bins of bin_us: whether the return window is covered and, if so,
  // the largest excess [m] of a return over the noise, 0 when none.
  struct ReturnTest {
    bool covered = false;
    double excess_m = 0.0;
  };
  ReturnTest return_beyond_noise(std::size_t rest_begin, double bin_us) const;

  EquilibriumThresholds thresholds_;
  std::vector<EquilibriumObservation> ring_;
  mutable std::vector<double> scratch_;  // one reading's series, for average_sigmas()
  std::size_t first_ = 0;
  std::size_t count_ = 0;
  std::size_t added_ = 0;       // observations added since reset()
  mutable SwayFit sway_;
  mutable bool last_check_sway_ = false;  // average() is then the fit's
  // Bin means of the sway window's position (time [s], x, y, z, count);
  // the return test keeps each bin's distance from rest in the time slot.
  mutable std::vector<std::array<double, 5>> bins_;
  // One coordinate's values and the fit's basis functions over the sway window.
  mutable std::vector<double> values_;
  mutable std::vector<Eigen::Vector3d> basis_;
};

}  // namespace cdpr::calibration
