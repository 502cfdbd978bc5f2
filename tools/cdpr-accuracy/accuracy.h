#pragma once
// Calibration accuracy over many simulated data sets (issue 4's acceptance):
// every run counts; a run whose fit fails is scored as if the nominal
// anchors and zero offsets had been kept.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/presets.h"
#include "solver/calibrate.h"

namespace cdpr::accuracy {

struct Case {
  sim::Preset preset = sim::Preset::kLarge;
  int poses = 35;
  double anchor_perturbation_m = 10.0;
  CableModelKind model = CableModelKind::kCatenary;
  double noise_scale = 1.0;  // multiplies the preset's sensor sigmas; 0 = noiseless
  std::optional<Eigen::Vector3d> workspace_min, workspace_max;  // preset's when empty
  int design_candidates = 0;  // sim/dataset.h: 0 = even spread, N = most informative of N
  int max_iterations = CalibrationOptions{}.max_iterations;
};

struct RunResult {
  std::uint64_t seed = 0;
  bool ok = false;
  std::string message;
  double anchor_error_m = 0.0;  // mean over cables of |a - a_true|
  double offset_error_m = 0.0;  // mean over cables of |l0 - l0_true|
  double normalised_sq_sum = 0.0;  // sum of (error / sigma)^2 over anchor axes and offsets
  int normalised_count = 0;
  int iterations = 0;
  // What the information allows, each a mean over cables of the anchor's
  // sigma norm sqrt(sx^2 + sy^2 + sz^2) (the RMS of |a - a_true|):
  double reported_sigma_m = 0.0;  // from the fit's own covariance (0 when it failed)
  double straight_bound_m = 0.0;  // Cramer-Rao, straight cables, true robot and poses (solver/pose_design.h)
};

RunResult run_case(const Case& c, std::uint64_t seed);

struct Distribution {
  double mean = 0.0, median = 0.0, p90 = 0.0, worst = 0.0;
};
Distribution distribution(std::vector<double> values);

struct Summary {
  int runs = 0;
  int failures = 0;
  Distribution anchor, offset;
  double normalised_rms = 0.0;  // over the successful runs
  double mean_reported_sigma_m = 0.0;  // over the successful runs
  double mean_straight_bound_m = 0.0;
  double mean_iterations = 0.0;
};
Summary summarise(const std::vector<RunResult>& runs);

}  // namespace cdpr::accuracy
