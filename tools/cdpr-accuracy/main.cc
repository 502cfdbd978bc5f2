// cdpr-accuracy: calibration accuracy over many simulated data sets, and the
// paper's Table I model check against the simulator's equilibrium.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <CLI/CLI.hpp>

#include "cdpr-accuracy/accuracy.h"
#include "cdpr-accuracy/model_check.h"
#include "cdpr-accuracy/replay.h"
#include "solver/calibration/chi_square.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"
#include "version/version.h"

namespace {

void print_row(const char* what, const cdpr::accuracy::Distribution& d) {
  std::printf("  %-22s mean %8.4f  median %8.4f  p90 %8.4f  worst %8.4f\n", what, d.mean, d.median, d.p90, d.worst);
}

// Per run: the error/sigma RMS against what the fit's own covariance
// predicts of it, and the Mahalanobis statistic (normalised_errors.h).
void print_run_honesty(const cdpr::accuracy::NormalisedErrors& e) {
  if (e.count == 0) return;
  std::printf("    error/sigma RMS %.2f, honest 90 %% range %.2f-%.2f (rank %.2f), P(outside %.1f-%.1f) %.2f; "
              "Mahalanobis e'C^-1e/n %.2f (p %.2f)\n",
              e.rms, e.rms_q05, e.rms_q95, e.rms_rank, cdpr::accuracy::kHonestRmsLow, cdpr::accuracy::kHonestRmsHigh,
              e.p_outside, e.mahalanobis, e.mahalanobis_p);
}

// Over the runs: how many per-run RMS fall outside the bounds against how
// many honest sigmas with each run's correlations would put there, and
// whether the Mahalanobis statistics follow chi-square(n) / n.
void print_honesty_summary(const std::vector<cdpr::accuracy::ReplayResult>& runs) {
  using cdpr::accuracy::kHonestRmsHigh;
  using cdpr::accuracy::kHonestRmsLow;
  int runs_stated = 0, outside = 0, mahalanobis_tail = 0, dof = 0;
  double expected_outside = 0.0, mahalanobis_sum = 0.0, rank_sum = 0.0, low = 1e300, high = 0.0;
  for (const auto& r : runs) {
    const cdpr::accuracy::NormalisedErrors& e = r.normalised;
    if (e.count == 0) continue;
    ++runs_stated;
    outside += e.rms < kHonestRmsLow || e.rms > kHonestRmsHigh;
    expected_outside += e.p_outside;
    mahalanobis_sum += e.mahalanobis * e.count;
    dof += e.count;
    mahalanobis_tail += e.mahalanobis_p < 0.05 || e.mahalanobis_p > 0.95;
    rank_sum += e.rms_rank;
    low = std::min(low, e.rms);
    high = std::max(high, e.rms);
  }
  if (runs_stated == 0) return;
  std::printf("  per run: error/sigma RMS %.2f-%.2f, %d of %d outside %.1f-%.1f (honest sigmas with each run's "
              "correlations: %.1f expected), mean rank %.2f (honest 0.50); Mahalanobis mean %.2f (honest 1.00, pooled "
              "p %.2f), %d of %d runs in its 5 %% tails (honest %.1f)\n",
              low, high, outside, runs_stated, kHonestRmsLow, kHonestRmsHigh, expected_outside, rank_sum / runs_stated,
              mahalanobis_sum / dof, cdpr::chi_square_upper_tail(mahalanobis_sum, dof), mahalanobis_tail, runs_stated,
              0.1 * runs_stated);
}

// --write-data: a replayed run's data set as cdpr-sim writes one, in
// <dir>/seed<N>, to fit again with cdpr-calib solve or diagnose.
bool write_run_data(const std::string& dir, const cdpr::accuracy::ReplayResult& r) {
  const std::filesystem::path out = std::filesystem::path(dir) / ("seed" + std::to_string(r.seed));
  std::error_code error;
  std::filesystem::create_directories(out, error);
  const std::pair<const char*, std::string> files[] = {
      {"robot.toml", cdpr::formats::format_robot_toml(r.nominal)},
      {"samples.csv", cdpr::formats::format_samples_csv(r.samples)},
      {"truth.toml", cdpr::formats::format_truth_toml(r.truth)}};
  for (const auto& [name, text] : files) {
    std::ofstream file(out / name, std::ios::binary | std::ios::trunc);
    file << text;
    file.close();
    if (!file) {
      std::fprintf(stderr, "cdpr-accuracy: cannot write %s\n", (out / name).c_str());
      return false;
    }
  }
  return true;
}

// --strategy: replays a waypoint strategy per seed and prints its table row.
int run_replay(const cdpr::accuracy::ReplayCase& c, const std::string& preset_name, const std::string& strategy,
               int seeds, int first_seed, bool verbose, const std::string& write_data) {
  std::vector<cdpr::accuracy::ReplayResult> runs;
  for (int s = 0; s < seeds; ++s) {
    runs.push_back(cdpr::accuracy::replay(c, static_cast<std::uint64_t>(first_seed + s)));
    const auto& r = runs.back();
    if (!write_data.empty() && !r.samples.empty() && !write_run_data(write_data, r)) return 1;
    if (verbose) {
      std::printf("seed %3llu %s time %6.1f min waypoints %2d skipped %d travel %7.1f m (nearest neighbour alone "
                  "%7.1f m) anchor mean %.4f worst %.4f m offset %.4f m largest sigma anchor %.4f offset %.4f m "
                  "error/sigma RMS %.2f forecast of waypoints left: mean |error| %.1f, bias %+.1f%s%s %s\n",
                  static_cast<unsigned long long>(r.seed), !r.ok ? "FAILED" : r.misfit ? "MISFIT" : "ok    ", r.robot_time_s / 60.0,
                  r.waypoints, r.skipped, r.travel_m, r.travel_nn_m, r.anchor_error_m, r.worst_anchor_error_m,
                  r.offset_error_m, r.largest_anchor_sigma_m, r.largest_offset_sigma_m,
                  r.normalised_count ? std::sqrt(r.normalised_sq_sum / r.normalised_count) : 0.0,
                  r.forecast_abs_error, r.forecast_bias, r.stop.empty() ? "" : " stop: ",
                  r.stop.c_str(), r.ok && !r.misfit ? "" : r.message.c_str());
      print_run_honesty(r.normalised);
    } else {
      std::fprintf(stderr, "\r%s: run %d/%d", strategy.c_str(), s + 1, seeds);
    }
  }
  if (!verbose) std::fprintf(stderr, "\n");
  double time_s = 0.0, waypoints = 0.0, anchor = 0.0, worst = 0.0, offset = 0.0, sq = 0.0, travel = 0.0, nn = 0.0;
  int count = 0, failures = 0, misfits = 0;
  for (const auto& r : runs) {
    const double n = static_cast<double>(runs.size());
    misfits += r.ok && r.misfit;
    time_s += r.robot_time_s / n;
    waypoints += r.waypoints / n;
    travel += r.travel_m / n;
    nn += r.travel_nn_m / n;
    anchor += r.anchor_error_m / n;
    worst = std::max(worst, r.worst_anchor_error_m);
    offset += r.offset_error_m / n;
    sq += r.normalised_sq_sum;
    count += r.normalised_count;
    failures += !r.ok;
  }
  std::printf("| %s, %.1f m off | %s | %.1f | %.1f | %.4f / %.4f | %.4f | %.2f |  (%d runs, %d failed, %d flagged "
              "by the model-fit test; mean travel %.0f m%s)\n",
              preset_name.c_str(), c.anchor_perturbation_m, strategy.c_str(), time_s / 60.0, waypoints, anchor, worst,
              offset, count ? std::sqrt(sq / count) : 0.0, static_cast<int>(runs.size()), failures, misfits, travel,
              nn > 0.0 ? (", nearest neighbour alone " + std::to_string(static_cast<int>(nn + 0.5)) + " m").c_str() : "");
  print_honesty_summary(runs);
  return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdpr-accuracy: calibration accuracy over many seeds of simulated data"};
  app.set_version_flag("--version", cdpr::version::version_text("cdpr-accuracy"));
  std::string preset_name = "large", model = "catenary";
  int poses = 35, seeds = 50, first_seed = 1;
  double perturbation = -1.0;
  std::vector<double> workspace;
  int design_candidates = 0;
  double noise_scale = 1.0;
  int max_iterations = cdpr::CalibrationOptions{}.max_iterations;
  bool model_check_only = false, verbose = false, truth_start = false;
  cdpr::sim::GrossErrors gross;
  cdpr::sim::HiddenEffects effects;
  std::vector<double> com_offset;
  app.add_option("--preset", preset_name, "large | small")->check(CLI::IsMember({"large", "small"}))->capture_default_str();
  app.add_option("--poses", poses, "static poses per data set")->capture_default_str();
  app.add_option("--seeds", seeds, "number of data sets (seeds first-seed ..)")->capture_default_str();
  app.add_option("--first-seed", first_seed, "first seed")->capture_default_str();
  app.add_option("--anchor-perturbation", perturbation,
                 "norm of the nominal anchors' error [m] (default: 10 large, 1 small)");
  app.add_option("--model", model, "catenary | rigid | both")->check(CLI::IsMember({"catenary", "rigid", "both"}))
      ->capture_default_str();
  app.add_option("--workspace", workspace, "waypoint box xmin,ymin,zmin,xmax,ymax,zmax [m] (default: the preset's)")
      ->delimiter(',')->expected(6);
  app.add_option("--design", design_candidates,
                 "0: poses spread evenly over the box; N: the most informative of N feasible candidates "
                 "(A-optimal on the nominal anchors, solver/calibration/pose_design.h)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--noise-scale", noise_scale,
                 "multiplies the preset's sensor noise; 0 = noiseless data fitted with the preset's sigmas, so the "
                 "reported sigmas are the model's Cramer-Rao bound for these poses")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--max-iterations", max_iterations, "Levenberg-Marquardt iterations per fit, at most")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--encoder-outliers", gross.encoder_fraction, "fraction of rows with a 0.5-2 m encoder error (cdpr-sim)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--force-spikes", gross.force_fraction, "fraction of rows with a 50-500 N load-cell spike (cdpr-sim)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--density-error", effects.density_error,
                 "hidden cable density error of the data (-0.999: nearly weightless cables)")
      ->check(CLI::Range(-0.9999, 10.0));
  app.add_option("--com-offset", com_offset, "hidden centre-of-mass offset x,y,z [m] of the data")
      ->delimiter(',')->expected(3);
  app.add_flag("--truth-start", truth_start,
               "also fit each data set from the true anchors and count fits whose final cost differs by more than "
               "1e-6 relative (a different minimum) or that fail");
  std::string strategy;
  cdpr::accuracy::ReplayCase replay_case;
  app.add_option("--strategy", strategy,
                 "replay a waypoint strategy of the daemon (spread and informative: --poses waypoints as a tour; "
                 "sequential: until the targets) and print robot time, waypoints and errors")
      ->check(CLI::IsMember({"spread", "informative", "sequential"}));
  app.add_option("--target-anchor-sigma", replay_case.sequential.target_anchor_sigma_m,
                 "sequential: stop when every anchor axis sigma is at most this [m]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--target-offset-sigma", replay_case.sequential.target_offset_sigma_m,
                 "sequential: and every offset sigma at most this [m]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--min-count", replay_case.sequential.min_count, "sequential: waypoints at least")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--max-count", replay_case.sequential.max_count, "sequential: waypoints at most")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--winch-speed", replay_case.sequential.winch_speed_mps, "robot-time model: winch profile speed [m/s]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--settle", replay_case.sequential.settle_s,
                 "robot-time model: wait for the sample after each move [s] (the daemon's sway window)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--score-horizon", replay_case.sequential.score_horizon_s,
                 "sequential: time added to each candidate's move and settle in its score [s]")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--row-noise-scale", replay_case.noise_scale,
                 "replay: a sample row's noise as a fraction of one reading's (the daemon averages a rest window of "
                 "about 100 readings)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  bool no_replan = false;
  std::string write_data;
  app.add_option("--write-data", write_data,
                 "replay: write each run's data set (robot.toml, samples.csv, truth.toml) to DIR/seed<N>");
  app.add_flag("--no-replan", no_replan,
               "sequential: keep the candidates planned from the nominal anchors (the daemon plans them again from "
               "its estimate)");
  std::vector<int> candidate_grid;
  app.add_option("--candidate-grid", candidate_grid,
                 "sequential: candidate grid xy,z (default: the daemon's [waypoints] grid_xy, grid_z)")
      ->delimiter(',')->expected(2)->check(CLI::PositiveNumber);
  app.add_flag("--model-check", model_check_only, "only run the Table I model check");
  app.add_flag("-v,--verbose", verbose,
               "one line per run (--strategy: and a line judging its sigmas against the fit's own covariance)");
  CLI11_PARSE(app, argc, argv);

  const cdpr::sim::Preset preset = *cdpr::sim::parse_preset(preset_name);
  if (model_check_only) {
    const cdpr::accuracy::ModelCheck c = cdpr::accuracy::model_check(preset, poses, first_seed);
    if (!c.error.empty()) {
      std::fprintf(stderr, "cdpr-accuracy: %s\n", c.error.c_str());
      return 2;
    }
    std::printf("model check (%s, %d poses): MPE-L %.3e %% (max %.3e %%)  MPE-F %.3e %% (max %.3e %%)\n",
                preset_name.c_str(), c.poses, c.mean_length_error_pct, c.max_length_error_pct, c.mean_force_error_pct,
                c.max_force_error_pct);
    std::printf("  lengths [%.1f, %.1f] m  forces [%.1f, %.1f] N\n", c.min_length_m, c.max_length_m, c.min_force_n,
                c.max_force_n);
    return 0;
  }

  if (!strategy.empty()) {
    replay_case.preset = preset;
    replay_case.strategy = strategy == "spread"        ? cdpr::accuracy::Strategy::kSpread
                           : strategy == "informative" ? cdpr::accuracy::Strategy::kInformative
                                                       : cdpr::accuracy::Strategy::kSequential;
    replay_case.count = poses;
    replay_case.replan = !no_replan;
    if (candidate_grid.size() == 2) {
      replay_case.candidate_grid_xy = candidate_grid[0];
      replay_case.candidate_grid_z = candidate_grid[1];
    }
    replay_case.anchor_perturbation_m = perturbation >= 0 ? perturbation : 0.3;
    return run_replay(replay_case, preset_name, strategy, seeds, first_seed, verbose, write_data);
  }

  cdpr::accuracy::Case c;
  c.preset = preset;
  c.poses = poses;
  c.anchor_perturbation_m = perturbation >= 0 ? perturbation : (preset == cdpr::sim::Preset::kLarge ? 10.0 : 1.0);
  if (workspace.size() == 6) {
    c.workspace_min = Eigen::Vector3d(workspace[0], workspace[1], workspace[2]);
    c.workspace_max = Eigen::Vector3d(workspace[3], workspace[4], workspace[5]);
  }
  c.design_candidates = design_candidates;
  c.noise_scale = noise_scale;
  c.max_iterations = max_iterations;
  c.gross_errors = gross;
  if (com_offset.size() == 3) effects.com_offset_platform = Eigen::Vector3d(com_offset[0], com_offset[1], com_offset[2]);
  c.effects = effects;
  c.compare_truth_start = truth_start;
  std::vector<cdpr::CableModelKind> models;
  if (model != "rigid") models.push_back(cdpr::CableModelKind::kCatenary);
  if (model != "catenary") models.push_back(cdpr::CableModelKind::kRigid);
  for (cdpr::CableModelKind kind : models) {
    c.model = kind;
    std::vector<cdpr::accuracy::RunResult> runs;
    for (int s = 0; s < seeds; ++s) {
      runs.push_back(cdpr::accuracy::run_case(c, static_cast<std::uint64_t>(first_seed + s)));
      const auto& r = runs.back();
      if (verbose) {
        std::printf("seed %3llu %s anchor %.4f m offset %.4f m iterations %d rejected clean %d planted %d/%d%s "
                    "chi2/dof %.3f truth-start gap %.1e %s\n",
                    static_cast<unsigned long long>(r.seed), r.ok ? "ok    " : "FAILED", r.anchor_error_m,
                    r.offset_error_m, r.iterations, r.clean_rows_rejected, r.recalled_encoder + r.recalled_force,
                    r.planted_encoder + r.planted_force, r.misfit ? " MISFIT" : "", r.chi_square_ratio, r.truth_start_cost_gap,
                    r.ok ? "" : r.message.c_str());
        for (const std::string& m : r.missed) std::printf("  missed %s\n", m.c_str());
      } else {
        std::fprintf(stderr, "\r%s model: run %d/%d", kind == cdpr::CableModelKind::kRigid ? "rigid" : "catenary",
                     s + 1, seeds);
      }
    }
    std::fprintf(stderr, "\n");
    const cdpr::accuracy::Summary s = cdpr::accuracy::summarise(runs);
    std::printf("%s / %d poses / %s model / perturbation %.1f m: %d runs, %d failed (scored as uncalibrated), "
                "mean iterations %.1f\n",
                preset_name.c_str(), poses, kind == cdpr::CableModelKind::kRigid ? "rigid" : "catenary",
                c.anchor_perturbation_m, s.runs, s.failures, s.mean_iterations);
    print_row("pulley error [m]", s.anchor);
    print_row("|offset error| [m]", s.offset);
    std::printf("  normalised error RMS (error/sigma): %.2f\n", s.normalised_rms);
    std::printf("  anchor sigma norm, mean [m]: reported by the fit %.4f, straight-cable Cramer-Rao bound %.4f\n",
                s.mean_reported_sigma_m, s.mean_straight_bound_m);
    std::printf("  gross errors rejected: encoder (>= 0.3 m) %d of %d, force %d of %d; clean rows rejected %d of %d "
                "(%.2f %%)\n",
                s.recalled_encoder, s.planted_encoder, s.recalled_force, s.planted_force, s.clean_rows_rejected,
                s.clean_rows, s.clean_rows ? 100.0 * s.clean_rows_rejected / s.clean_rows : 0.0);
    std::printf("  model-fit test flagged %d of %d runs; %d refused for too many gross errors\n", s.misfits, s.runs,
                s.refusals);
    if (truth_start) {
      std::printf("  truth-started minimum: %d runs differ (> 1e-6 relative cost, or a failed fit); worst gap %.1e\n",
                  s.truth_start_mismatches, s.worst_truth_start_gap);
    }
  }
  return 0;
}
