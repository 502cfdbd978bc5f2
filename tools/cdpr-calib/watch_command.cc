#include "watch_command.h"

#include <cmath>
#include <cstdio>
#include <fstream>

#include "report.h"
#include "solver/operation/health_watch.h"
#include "solver/operation/refit.h"
#include "src/formats/calibration_toml.h"

namespace cdpr::tools {
namespace {

std::string format(const char* pattern, double a, double b) {
  char text[96];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

// A term's fitted change with its sigma, in its units.
std::string term_value_text(const TermEstimate& e) {
  const auto pair = [&](int j, const char* unit) {
    return format("%+.4f (sigma %.4f) ", e.value(j), e.sigma(j)) + unit;
  };
  switch (e.term) {
    case FaultTerm::kEncoderOffset: return pair(0, "m");
    case FaultTerm::kCableElongation: return pair(0, "m longer at the reference payout");
    case FaultTerm::kLoadCellBias: return pair(0, "N");
    case FaultTerm::kAnchor:
      return "moved by " + format("%.4f m (x %+.4f", e.value.norm(), e.value(0)) + format(", y %+.4f, z %+.4f)", e.value(1), e.value(2)) +
             format(" sigma %.4f %.4f", e.sigma(0), e.sigma(1)) + format(" %.4f m", e.sigma(2), 0.0);
    case FaultTerm::kLoad:
      return "mass " + pair(0, "kg") + ", centre of mass " + format("%+.4f %+.4f", e.value(1), e.value(2)) +
             format(" %+.4f m (sigma %.4f", e.value(3), e.sigma(1)) + format(" %.4f %.4f)", e.sigma(2), e.sigma(3));
  }
  return "?";
}

std::string term_line(const TermEstimate& e) {
  return fault_term_name(e.term, e.cable) + " (" + fault_term_meaning(e.term, e.cable) + "): " + term_value_text(e) +
         format(", chi-square drop %.1f, AIC gain %.1f", e.chi_square_drop, e.aic_gain());
}

// The worst anchor and offset errors of `c` against `truth` [m].
std::pair<double, double> worst_errors(const Calibration& c, const Truth& truth) {
  double anchor = 0.0, offset = 0.0;
  for (std::size_t i = 0; i < c.winches.size() && i < truth.winches.size(); ++i) {
    anchor = std::max(anchor, (c.winches[i].anchor_world - truth.winches[i].anchor_world).norm());
    offset = std::max(offset, std::abs(c.winches[i].offset_m - truth.winches[i].offset_m));
  }
  return {anchor, offset};
}

void print_refit_changes(const Calibration& committed, const Calibration& refit) {
  for (std::size_t i = 0; i < refit.winches.size(); ++i) {
    const WinchCalibration &a = committed.winches[i], &b = refit.winches[i];
    if (a.offset_m != b.offset_m) {
      std::printf("  offset[%zu]: %.4f -> %.4f m (sigma %.4f)\n", i, a.offset_m, b.offset_m, b.offset_sigma_m);
    }
    if (a.anchor_world != b.anchor_world) {
      std::printf("  anchor[%zu]: %.4f %.4f %.4f -> %.4f %.4f %.4f m (sigma %.4f %.4f %.4f)\n", i, a.anchor_world.x(),
                  a.anchor_world.y(), a.anchor_world.z(), b.anchor_world.x(), b.anchor_world.y(), b.anchor_world.z(),
                  b.anchor_sigma.x(), b.anchor_sigma.y(), b.anchor_sigma.z());
    }
  }
}

}  // namespace

void add_watch_command(CLI::App& app, WatchArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "watch",
      "Replay the health test over the rows in order: a sequential change test per cable and term against the "
      "committed calibration; prints when it fired, which term changed (by how much, since which rest) and the "
      "re-fit it offers");
  add_operation_inputs(*cmd, args.inputs);
  cmd->add_option("--refit-output", args.refit_path, "write the offered re-fit (calibration.toml) here");
  cmd->add_option("--calibration-samples", args.calibration_samples_path,
                  "the samples.csv the calibration was fitted on: its anchors' and offsets' joint covariance, "
                  "which tells the calibration's own error from a change (else its per-axis sigmas)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--offsets-only", args.offsets_only, "re-fit all four encoder offsets instead of the named term");
  cmd->add_option("--truth", args.truth_path,
                  "truth.toml of the robot after the change (cdpr-sim --rests: truth_after.toml): print the "
                  "committed and re-fitted calibration's worst errors")
      ->check(CLI::ExistingFile);
  cmd->add_option("--false-alarm-rests", args.clean_rests_per_false_alarm,
                  "designed false-alarm rate: at most one per this many clean rests")
      ->check(CLI::Range(10.0, 1e12))->capture_default_str();
  cmd->add_option("--calibration-error", args.calibration_error,
                  "the committed calibration's own error in the test: tracked (estimated from the rests so far, the "
                  "test on the innovations), predictive (only the scores' variance widened by it) or ignored")
      ->check(CLI::IsMember({"tracked", "predictive", "ignored"}))->capture_default_str();
  cmd->add_option("--calibration-error-rests", args.calibration_error_rests,
                  "tracked: estimate it over this many checked rests, then hold it (0: every rest)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_option("--anchor-misnaming-rate", args.anchor_misnaming_rate,
                  "name an anchor move over its cable's offset slip only when at most this fraction of slips would be")
      ->check(CLI::Range(1e-9, 0.5))->capture_default_str();
  cmd->add_flag("--no-measured-pose", args.no_measured_pose, "ignore the rows' onboard poses (cables and load cell only)");
  cmd->add_flag("-v,--verbose", args.verbose, "a line per rest: residuals and the largest statistic");
}

int run_watch(const WatchArgs& args) {
  const std::optional<OperationInputs> in = read_operation_inputs(args.inputs);
  if (!in) return 1;
  HealthWatchOptions options;
  options.clean_rests_per_false_alarm = args.clean_rests_per_false_alarm;
  options.use_measured_pose = !args.no_measured_pose;
  options.calibration_error = args.calibration_error == "ignored"      ? CalibrationErrorHandling::kIgnored
                              : args.calibration_error == "predictive" ? CalibrationErrorHandling::kPredictive
                                                                       : CalibrationErrorHandling::kTracked;
  options.calibration_error_rests = args.calibration_error_rests;
  options.anchor_misnaming_rate = args.anchor_misnaming_rate;
  if (!args.calibration_samples_path.empty() &&
      !read_calibration_covariance(args.calibration_samples_path, *in, options.height_sigma_m, options.calibration_covariance)) {
    return 1;
  }
  HealthWatch watch(in->robot, in->calibration, options);
  std::printf("health watch: %zu rests, threshold h = %.2f (at most one false alarm per %g clean rests)\n",
              in->rests.size(), watch.threshold(), args.clean_rests_per_false_alarm);
  int unchecked = 0;
  double offset_shift_squares = 0.0;  // the offsets' delta^2 summed over the checked rests and cables
  for (const Sample& rest : in->rests) {
    const RestCheck check = watch.add_rest(rest);
    if (!check.checked) {
      ++unchecked;
      std::printf("rest %d (id %d): not checked: %s\n", check.rest, check.sample_id, check.why.c_str());
      continue;
    }
    for (const TermStatistic& s : check.statistics) {
      if (s.term == FaultTerm::kEncoderOffset) offset_shift_squares += s.standardised_shift * s.standardised_shift;
    }
    if (args.verbose) {
      const TermStatistic* top = &check.statistics.front();
      for (const TermStatistic& s : check.statistics) {
        if (std::max(s.cusum_up, s.cusum_down) > std::max(top->cusum_up, top->cusum_down)) top = &s;
      }
      std::printf("rest %d (id %d): encoders %+.2f %+.2f %+.2f %+.2f force %+.2f sigma; pose diff max %.2f sigma; "
                  "largest CUSUM %s %.2f\n",
                  check.rest, check.sample_id, check.encoder_residual_sigma[0], check.encoder_residual_sigma[1],
                  check.encoder_residual_sigma[2], check.encoder_residual_sigma[3], check.force_residual_sigma,
                  check.pose_difference_sigma.cwiseAbs().maxCoeff(), fault_term_name(top->term, top->cable).c_str(),
                  std::max(top->cusum_up, top->cusum_down));
    }
    if (check.fired) {
      const StaleFinding& f = *watch.finding();
      std::printf("calibration stale at rest %d (id %d): %s crossed h, since rest %d (id %d)\n", f.fired_at_rest,
                  f.fired_at_sample_id, fault_term_name(f.statistic.term, f.statistic.cable).c_str(), f.since_rest,
                  f.since_sample_id);
      std::printf("  first estimate: %s\n", term_line(f.term).c_str());
    }
  }

  const int checked = static_cast<int>(in->rests.size()) - unchecked;
  // The RMS standardised shift of a designed offset slip: the CUSUM needs
  // about h / (delta^2 / 2) rests to flag one.
  const double offset_delta = checked > 0 ? std::sqrt(offset_shift_squares / (kCableCount * checked)) : 0.0;
  std::printf("a designed offset slip (%.3f m) moves a rest's score by %.2f sigma (RMS): flagged after about %.1f "
              "rests\n",
              options.offset_shift_m, offset_delta,
              offset_delta > 0.0 ? watch.threshold() / (offset_delta * offset_delta / 2.0) : 0.0);
  std::string summary = "summary: rests=" + std::to_string(in->rests.size()) +
                        " unchecked=" + std::to_string(unchecked) + format(" offset_delta=%.2f", offset_delta, 0.0);
  if (!watch.stale()) {
    std::printf("the calibration held over %zu rests\n", in->rests.size());
    std::printf("%s stale=0\n", summary.c_str());
    return 0;
  }
  const StaleFinding& f = *watch.finding();
  std::printf("finding over the %d rests since rest %d: %s\n", f.rests_fitted, f.since_rest, term_line(f.term).c_str());
  std::string alike;
  for (const TermEstimate& e : f.alike) {
    std::printf("  looks alike: %s\n", term_line(e).c_str());
    alike += (alike.empty() ? "" : ",") + fault_term_name(e.term, e.cable);
  }
  if (!f.calibration_fault()) std::printf("  not a calibration fault: update robot.toml's mass and centre of mass\n");
  if (const std::optional<AnchorOrOffset>& a = f.anchor_or_offset) {
    std::printf("  anchor[%d] or offset[%d]: 2 ln LR %.1f (anchor named above %.1f): %s; the rests resolve a move "
                "beyond an offset change to %.4f m (1 sigma) at best, the fitted move is %.1f of those sigmas%s\n",
                a->cable, a->cable, a->log_likelihood_ratio, a->margin,
                a->anchor_named() ? "the anchor" : "cannot tell, the offset is the simpler", a->best_sigma_m,
                a->fitted_move_sigmas, a->separable() ? "" : " (too few for the margin: the rests do not span the "
                                                              "cable's directions enough)");
  }
  summary += " stale=1 fired_rest=" + std::to_string(f.fired_at_rest) + " onset_rest=" + std::to_string(f.since_rest) +
             " term=" + fault_term_name(f.term.term, f.term.cable) + " alike=" + (alike.empty() ? "-" : alike);
  if (const std::optional<AnchorOrOffset>& a = f.anchor_or_offset) {
    summary += format(" anchor_2lnlr=%.1f anchor_move_sigmas=%.1f", a->log_likelihood_ratio, a->fitted_move_sigmas) +
               format(" anchor_best_sigma_m=%.4f", a->best_sigma_m, 0.0);
  }

  RefitRequest request = refit_request_for(f);
  if (args.offsets_only) request.offsets_only = true;
  std::string why;
  const std::optional<Calibration> refit =
      refit_from_rests(in->robot, in->calibration, watch.rests_since_onset(), request, {}, &why);
  if (!refit) {
    std::printf("no re-fit offered: %s\n", why.c_str());
  } else {
    std::printf("offered re-fit (%s from %d rests; not applied):\n",
                request.offsets_only ? "the four offsets" : fault_term_name(request.term, request.cable).c_str(),
                refit->samples);
    print_refit_changes(in->calibration, *refit);
    double delta = 0.0;  // the largest change of a re-fitted value, signed
    for (std::size_t i = 0; i < refit->winches.size(); ++i) {
      const double offset = refit->winches[i].offset_m - in->calibration.winches[i].offset_m;
      const double anchor = (refit->winches[i].anchor_world - in->calibration.winches[i].anchor_world).norm();
      if (std::abs(offset) > std::abs(delta)) delta = offset;
      if (anchor > std::abs(delta)) delta = anchor;
    }
    summary += format(" refit_delta_m=%.4f", delta, 0.0);
    if (!args.refit_path.empty()) {
      Calibration written = *refit;
      written.created = utc_timestamp_now();
      std::ofstream file(args.refit_path, std::ios::trunc);
      file << formats::format_calibration_toml(written);
      file.close();
      if (!file) {
        std::fprintf(stderr, "cdpr-calib: cannot write %s\n", args.refit_path.c_str());
        return 1;
      }
      std::printf("wrote %s\n", args.refit_path.c_str());
    }
  }
  if (!args.truth_path.empty()) {
    auto truth = formats::read_truth_toml(args.truth_path);
    if (!truth) {
      std::fprintf(stderr, "cdpr-calib: %s\n", truth.error().message().c_str());
      return 1;
    }
    const auto [anchor, offset] = worst_errors(in->calibration, *truth);
    summary += format(" committed_anchor_m=%.4f committed_offset_m=%.4f", anchor, offset);
    if (refit) {
      const auto [refit_anchor, refit_offset] = worst_errors(*refit, *truth);
      summary += format(" refit_anchor_m=%.4f refit_offset_m=%.4f", refit_anchor, refit_offset);
    }
  }
  std::printf("%s\n", summary.c_str());
  return 3;
}

}  // namespace cdpr::tools
