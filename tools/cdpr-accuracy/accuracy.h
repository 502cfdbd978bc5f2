#pragma once
// Calibration accuracy over many simulated data sets (docs/calibration.md):
// every run counts; a run whose fit fails is scored as if the nominal
// anchors and zero offsets had been kept.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/outliers.h"
#include "sim/presets.h"
#include "sim/true_robot.h"
#include "solver/calibration/calibrate.h"

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
  sim::GrossErrors gross_errors;  // planted in the data (sim/outliers.h)
  sim::HiddenEffects effects;     // hidden in the data (mis-modelled data for the model-fit test)
  // Also fit from the true anchors and compare the final costs (the same
  // minimum within 1e-6 relative, or not).
  bool compare_truth_start = false;
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
  double straight_bound_m = 0.0;  // Cramer-Rao, straight cables, true robot and poses (solver/calibration/pose_design.h)
  // Gross errors: planted (encoder >= 0.3 m, and force spikes), how many of
  // them were rejected, and clean rows (no planted error) rejected.
  int planted_encoder = 0, recalled_encoder = 0, planted_force = 0, recalled_force = 0;
  int clean_rows = 0, clean_rows_rejected = 0;
  std::vector<std::string> missed;   // each planted reading not reported, and why
  bool misfit = false;               // the model-fit test flagged the fit
  bool refused = false;              // refused for too many gross errors
  double chi_square_ratio = 0.0;     // chi2 / dof of the final fit
  double cost_final = 0.0;
  bool truth_start_ok = true;        // compare_truth_start: it converged too
  double truth_start_cost_gap = 0.0; // (cost - cost from truth) / cost from truth
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
  int planted_encoder = 0, recalled_encoder = 0, planted_force = 0, recalled_force = 0;
  int clean_rows = 0, clean_rows_rejected = 0;
  std::vector<std::string> missed;   // each planted reading not reported, and why
  int misfits = 0;
  int refusals = 0;
  int truth_start_mismatches = 0;  // |cost gap| > 1e-6 or one of the two fits failed
  double worst_truth_start_gap = 0.0;
};
Summary summarise(const std::vector<RunResult>& runs);

}  // namespace cdpr::accuracy
