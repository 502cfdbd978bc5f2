#include "solver/calibration/calibrate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "solver/calibration/calibration_stages.h"
#include "solver/calibration/gross_errors.h"
#include "solver/calibration/model_fit_check.h"
#include "solver/calibration/noise_components.h"
#include "solver/calibration/refusal_cause.h"
#include "solver/calibration/row_attribution.h"
#include "solver/calibration/single_fit.h"
#include "solver/calibration/start_selection.h"
#include "solver/calibration/term_tests.h"

namespace cdpr {

namespace {

// Sets of at most this many rows, where one row is a large share of the
// data, get the leave-one-row-out hypotheses and the swap test: each is a
// handful of full fits, too many for large sets, which do not need them.
constexpr std::size_t kSmallSetRows = 20;

// "; N readings with gross errors left out" on a fit's message.
void note_left_out(CalibrationResult& fit) {
  fit.message += "; " + std::to_string(fit.gross_errors.size()) + " readings with gross errors left out";
}

bool has_anchors(const CalibrationResult& result) {
  return result.calibration.winches.size() == static_cast<std::size_t>(kCableCount);
}

// `robot` with the anchors of a fit as its nominal ones: a start for another fit.
Robot started_at(const Robot& robot, const CalibrationResult& fit) {
  Robot start = robot;
  for (int i = 0; i < kCableCount; ++i) start.winches[i].anchor_world = fit.calibration.winches[i].anchor_world;
  return start;
}

CalibrationResult calibrate_with_restart(const Robot& robot, const std::vector<Sample>& samples,
                                         const CalibrationOptions& options) {
  // A fit to keep: converged, or gross errors to leave out that are few
  // enough (a start that ended in a wrong minimum makes many rows look bad).
  auto usable = [&](const CalibrationResult& r) {
    return r.ok || (!r.gross_errors.empty() &&
                    gross_error_row_fraction(r, samples.size()) <= options.max_rejected_fraction);
  };
  CalibrationResult first = calibrate_once(robot, samples, options);
  if (usable(first) || options.cable_model != CableModelKind::kCatenary) return first;
  std::string why = "from the nominal anchors: " + first.message;
  // One fallback: a fit with `start_options` whose anchors start the fit
  // asked for; that fit when usable. `failed` and `after` name it in `why`.
  auto restart = [&](const char* name, const CalibrationOptions& start_options, const char* failed,
                     const char* after) -> std::optional<CalibrationResult> {
    StageScope stage(name, true);
    const CalibrationResult start = calibrate_once(robot, samples, start_options);
    if (start.calibration.winches.empty()) {
      why += std::string("; ") + failed + start.message;
      stage.finish("not kept: the fit for its start failed: " + start.message);
      return std::nullopt;
    }
    CalibrationResult fit = calibrate_once(started_at(robot, start), samples, options);
    if (!usable(fit)) {
      why += std::string("; ") + after + fit.message;
      stage.finish("not kept: " + fit.message);
      return std::nullopt;
    }
    stage.finish("kept");
    return fit;
  };
  // A tight Eq. (15) makes the cost landscape narrow; far from the solution
  // LM can stall where the anchors are unobservable. Continuation: solve with
  // a ten times looser height consistency from the nominal anchors, then
  // with the requested one from there.
  CalibrationOptions loose = options;
  loose.height_sigma_m *= 10.0;
  if (std::optional<CalibrationResult> second =
          restart("restart with a ten times looser height consistency", loose, "with a looser height consistency: ",
                  "after a looser height consistency: ")) {
    second->message += " (after a restart with a looser height consistency: the first solve stopped where the "
                       "anchors were unobservable)";
    return *second;
  }
  // Straight cables have no sag to start and converge from farther away: a
  // rigid fit's anchors as the start.
  CalibrationOptions rigid = options;
  rigid.cable_model = CableModelKind::kRigid;
  rigid.effects.clear();
  if (std::optional<CalibrationResult> third = restart("restart from a rigid fit's anchors", rigid,
                                                       "the rigid fit for a start failed too: ",
                                                       "from a rigid fit's anchors: ")) {
    third->message += " (started from a rigid fit's anchors: " + why + ")";
    return *third;
  }
  if (first.gross_errors.empty()) first.message = "no start converged (" + why + ")";
  return first;
}

// The readings of a refusal in words, the worst few: the report and the
// summary's list have them all.
constexpr std::size_t kNamedReadings = 5;
std::string rows_text(std::vector<SensorReading> readings) {
  std::stable_sort(readings.begin(), readings.end(), [](const SensorReading& a, const SensorReading& b) {
    return std::abs(a.value) > std::abs(b.value);
  });
  std::string text;
  for (std::size_t j = 0; j < std::min(readings.size(), kNamedReadings); ++j) {
    const SensorReading& r = readings[j];
    char line[128];
    std::snprintf(line, sizeof line, "%srow %d %s%s %+.1f sigma", text.empty() ? "" : ", ", r.row,
                  sensor_name(r.sensor),
                  r.sensor == SensorKind::kEncoder ? (" " + std::to_string(r.cable)).c_str() : "", r.value);
    text += line;
  }
  if (readings.size() > kNamedReadings) {
    text += " and " + std::to_string(readings.size() - kNamedReadings) + " more (the gross-error list)";
  }
  return text;
}

// The gross errors left out, the fit redone by least squares from the
// robust fit's anchors.
CalibrationResult refit_without(const Robot& robot, const std::vector<Sample>& samples,
                                const CalibrationOptions& options, const CalibrationResult& robust) {
  // Refused when the readings flagged (a hypothesis row's readings are not
  // flagged, only tentative: the final test below decides them) or, after
  // the final test, those confirmed lie on more rows than allowed.
  auto refusal = [&](const std::vector<SensorReading>& readings) -> std::optional<CalibrationResult> {
    CalibrationResult refused = robust;
    refused.gross_errors = readings;
    const double fraction = gross_error_row_fraction(refused, samples.size());
    if (fraction <= options.max_rejected_fraction) return std::nullopt;
    refused.ok = false;
    refused.refusal = Refusal::kSensorFault;
    refused.calibration.rejected.clear();
    char text[256];
    std::snprintf(text, sizeof text, "%.0f of %zu rows (%.0f %%) have gross errors, more than the %.0f %% allowed; worst: ",
                  std::round(fraction * static_cast<double>(samples.size())), samples.size(), 100.0 * fraction,
                  100.0 * options.max_rejected_fraction);
    refused.message = text + rows_text(readings);
    return refused;
  };
  std::vector<SensorReading> flagged;
  for (const SensorReading& r : robust.gross_errors) {
    if (std::isfinite(r.value)) flagged.push_back(r);
  }
  StageScope stage("refit without the gross errors", false);
  if (auto refused = refusal(flagged)) {
    stage.finish("refused: " + refused->message);
    return *refused;
  }
  const std::vector<Sample> kept = leave_out(samples, robust.gross_errors, options.cable_model);
  Robot restart = robot;
  for (int i = 0; i < kCableCount; ++i) restart.winches[i].anchor_world = robust.calibration.winches[i].anchor_world;
  CalibrationOptions plain = options;
  plain.robust = false;
  CalibrationResult refit = calibrate_with_restart(restart, kept, plain);
  // The final test: a left-out reading that the refit predicts within the
  // threshold was no gross error (a robust fit from far off can end where
  // good readings look bad); it goes back in and the fit is redone once.
  // Where the model misfits everywhere (chi2 / dof above 1) the bar rises
  // with the misfit: a reading then off by a few times the noise is the
  // missing effect's signature, which diagnose needs, not a gross error.
  const double misfit_scale =
      refit.degrees_of_freedom > 0 ? std::max(1.0, std::sqrt(refit.chi_square / refit.degrees_of_freedom)) : 1.0;
  const std::vector<SensorReading> confirmed = confirm_left_out(
      robust.gross_errors, refit.left_out_residuals, refit.ok, options.rejection_threshold_sigma * misfit_scale);
  record_stage("final test of the readings left out",
               std::to_string(robust.gross_errors.size() - confirmed.size()) + " of " +
                   std::to_string(robust.gross_errors.size()) + " predicted within the threshold: put back" +
                   (confirmed.size() < robust.gross_errors.size() ? ", fit redone" : ""));
  if (confirmed.size() < robust.gross_errors.size()) {
    // A failed refit has no anchors: the robust fit's stay the start.
    if (has_anchors(refit)) {
      for (int i = 0; i < kCableCount; ++i) restart.winches[i].anchor_world = refit.calibration.winches[i].anchor_world;
    }
    refit = calibrate_with_restart(restart, leave_out(samples, confirmed, options.cable_model), plain);
  }
  if (auto refused = refusal(confirmed)) {
    stage.finish("refused: " + refused->message);
    return *refused;
  }
  refit.gross_errors = confirmed;
  refit.calibration.rejected = confirmed;
  if (refit.ok) note_left_out(refit);
  stage.finish(std::to_string(confirmed.size()) + " readings left out; " +
               (refit.ok ? "fit ok" : "fit failed: " + refit.message));
  return refit;
}

// When the robust fit flags more rows than allowed on a small set, one
// high-leverage gross error may have pulled the fit into a basin where good
// rows look bad. Each row is left out in turn and the robust fit redone; the
// hypothesis that flags the fewest rows wins. Its flagged readings and every
// reading of the row it left out become the candidates to leave out: the
// final test in refit_without puts back those the refit predicts within the
// threshold. Nothing when the set is large or no hypothesis brings the
// flagged rows within the allowed fraction.
// `fallback`: run because the fit flagged too many rows (not to challenge a fit).
std::optional<CalibrationResult> consensus_start(const Robot& robot, const std::vector<Sample>& samples,
                                                 const CalibrationOptions& options, bool fallback) {
  if (samples.size() > kSmallSetRows || samples.size() < 3) return std::nullopt;
  StageScope stage("row hypotheses: each row left out in turn", fallback, StageScope::Inner::kSummaryOnly);
  std::optional<CalibrationResult> best;
  std::size_t best_row = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    std::vector<Sample> rest = samples;
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(k));
    CalibrationResult fit = calibrate_with_restart(robot, rest, options);
    if (fit.calibration.winches.empty() || (!fit.ok && fit.gross_errors.empty())) continue;
    if (gross_error_row_fraction(fit, rest.size()) > options.max_rejected_fraction) continue;
    if (!best || fit.gross_errors.size() < best->gross_errors.size()) {
      best = std::move(fit);
      best_row = k;
    }
  }
  if (!best) {
    stage.finish(std::to_string(samples.size()) + " rows tried; none brings the rows with gross errors within the "
                 "allowed fraction");
    return std::nullopt;
  }
  CalibrationResult candidate = *best;
  candidate.ok = false;
  const int id = samples[best_row].id;
  stage.finish(std::to_string(samples.size()) + " rows tried; best leaves out row " + std::to_string(id) + " (" +
               std::to_string(best->gross_errors.size()) + " gross errors beside it)");
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < kCableCount; ++i) candidate.gross_errors.push_back({id, SensorKind::kEncoder, i, unknown});
  if (options.cable_model == CableModelKind::kCatenary) {
    candidate.gross_errors.push_back({id, SensorKind::kForce, robot.reference_cable, unknown});
  }
  return candidate;
}

// On a small set, a gross error can be absorbed and stay in while a good
// reading is left out in its place: by its row's pose and reference force
// once another reading of the row is left out (above all the load cell,
// whose absence frees both force components), or by its cable's anchor and
// offset, which then make the same cable's reading of another row look bad.
// A row may also hold two gross errors of which one was found. So for each
// reading left out, every other reading of its row is tried in its place
// and beside it, the same sensor of every other row in its place, and the
// reading itself back in; the fit is redone by least squares each time. The best
// change is kept when a reading it newly leaves out is predicted beyond the
// threshold and the fit explains the readings better (start_score) without
// starting to misfit; then the search starts over, a bounded number of times.
//
// A fit refused for too many rows with gross errors gets the search too:
// an absorbed gross error makes its cable's good readings look bad on
// other rows, and those rows can be what tips the count over the bar. Its
// readings are left out and the fit redone anyway, the search run from
// there, and the result kept only when it leaves readings out on no more
// rows than allowed and passes the model-fit test; otherwise the refusal
// stands. Changes only put readings back or move them, so the rows left
// out never grow, and each reading still out is predicted beyond the
// threshold or costs the fit more than leaving it out.
CalibrationResult swap_within_rows(const Robot& robot, const std::vector<Sample>& samples,
                                   const CalibrationOptions& options, CalibrationResult result) {
  if (samples.size() > kSmallSetRows || options.cable_model != CableModelKind::kCatenary) return result;
  CalibrationOptions plain = options;
  plain.robust = false;
  const bool refused = !result.ok;
  if (refused) {
    if (result.gross_errors.empty() || !has_anchors(result) ||
        gross_error_row_fraction(result, samples.size()) <= options.max_rejected_fraction) {
      return result;
    }
    CalibrationResult fit = calibrate_with_restart(started_at(robot, result),
                                                   leave_out(samples, result.gross_errors, options.cable_model), plain);
    if (!fit.ok) return result;
    fit.gross_errors = result.gross_errors;
    fit.calibration.rejected = result.gross_errors;
    note_left_out(fit);
    assess_model_fit(fit, options);
    const CalibrationResult searched = swap_within_rows(robot, samples, options, std::move(fit));
    const bool within = gross_error_row_fraction(searched, samples.size()) <= options.max_rejected_fraction;
    return within && !searched.misfit ? searched : result;
  }
  StageScope stage("swap test: readings left out moved within row and cable", false,
                   StageScope::Inner::kSummaryOnly);
  int tried = 0, kept = 0;
  auto same = [](const SensorReading& a, const SensorReading& b) {
    return a.row == b.row && a.sensor == b.sensor && a.cable == b.cable;
  };
  auto left_out = [&](const SensorReading& in) {
    return std::any_of(result.gross_errors.begin(), result.gross_errors.end(),
                       [&](const SensorReading& r) { return same(r, in); });
  };
  // Each change of the set left out: the fit, or nothing when it is not kept.
  auto try_change = [&](std::vector<SensorReading> changed, const SensorReading* in) -> std::optional<CalibrationResult> {
    ++tried;
    CalibrationResult refit =
        calibrate_with_restart(started_at(robot, result), leave_out(samples, changed, options.cable_model), plain);
    if (!refit.ok) return std::nullopt;
    if (in) {
      const auto predicted = std::find_if(refit.left_out_residuals.begin(), refit.left_out_residuals.end(),
                                          [&](const SensorReading& p) { return same(p, *in); });
      if (predicted == refit.left_out_residuals.end() ||
          !(std::abs(predicted->value) > options.rejection_threshold_sigma)) {
        return std::nullopt;
      }
      for (SensorReading& r : changed) {
        if (same(r, *in)) r.value = predicted->value;
      }
    }
    refit.gross_errors = changed;
    refit.calibration.rejected = changed;
    note_left_out(refit);
    assess_model_fit(refit, options);
    if (refit.misfit && !result.misfit) return std::nullopt;
    return refit;
  };
  const int max_changes = 2 * static_cast<int>(result.gross_errors.size()) + 2;
  for (int change = 0; change < max_changes; ++change) {
    std::optional<CalibrationResult> best;
    auto consider = [&](std::optional<CalibrationResult> fit) {
      if (fit && better_fit(*fit, best ? *best : result, options.rejection_threshold_sigma)) best = std::move(fit);
    };
    for (std::size_t g = 0; g < result.gross_errors.size(); ++g) {
      const SensorReading out = result.gross_errors[g];
      std::vector<SensorReading> peers;
      for (const Sample& sample : samples) {
        if (sample.id == out.row) {
          for (int i = 0; i < kCableCount; ++i) peers.push_back({out.row, SensorKind::kEncoder, i, 0.0});
          peers.push_back({out.row, SensorKind::kForce, robot.reference_cable, 0.0});
        } else {
          peers.push_back({sample.id, out.sensor, out.cable, 0.0});
        }
      }
      for (const SensorReading& in : peers) {
        if (left_out(in)) continue;
        std::vector<SensorReading> swapped = result.gross_errors;
        swapped[g] = in;
        consider(try_change(swapped, &in));
        if (in.row != out.row) continue;
        std::vector<SensorReading> beside = result.gross_errors;
        beside.push_back(in);
        consider(try_change(beside, &in));
      }
      std::vector<SensorReading> back = result.gross_errors;
      back.erase(back.begin() + static_cast<std::ptrdiff_t>(g));
      consider(try_change(back, nullptr));
    }
    if (!best) break;
    result = std::move(*best);
    ++kept;
  }
  stage.finish(std::to_string(tried) + " refits; " + std::to_string(kept) + " changes kept");
  return result;
}

}  // namespace

std::vector<Sample> leave_out(const std::vector<Sample>& samples, const std::vector<SensorReading>& gross_errors,
                              CableModelKind cable_model) {
  std::vector<Sample> kept;
  for (Sample s : samples) {
    bool any = false;
    for (const SensorReading& r : gross_errors) {
      if (r.row != s.id) continue;
      any = true;
      if (r.sensor == SensorKind::kForce) s.force_left_out = true;
      else if (r.cable >= 0 && r.cable < kCableCount) s.encoder_left_out[r.cable] = true;
    }
    if (!any || cable_model == CableModelKind::kCatenary) kept.push_back(s);
  }
  return kept;
}

namespace {

// calibrate() from one start: the robust fit, the gross errors left out and
// the fit redone, the leave-one-row-out hypotheses on small sets.
CalibrationResult calibrate_from(const Robot& robot, const std::vector<Sample>& samples,
                                 const CalibrationOptions& options) {
  CalibrationResult result = calibrate_with_restart(robot, samples, options);
  bool hypothesis = false;
  if (!result.ok && !result.gross_errors.empty() &&
      gross_error_row_fraction(result, samples.size()) > options.max_rejected_fraction) {
    if (auto candidate = consensus_start(robot, samples, options, true)) {
      result = std::move(*candidate);
      hypothesis = true;
    }
  }
  if (result.ok || result.gross_errors.empty()) {
    if (result.ok) assess_model_fit(result, options);
    return result;
  }
  const CalibrationResult robust = result;
  result = refit_without(robot, samples, options, robust);
  if (!result.ok) return result;
  assess_model_fit(result, options);
  if (hypothesis) return result;
  // On a small set, one gross error can be absorbed by its cable's anchor
  // and offset and stay in, while good readings are left out in its place,
  // and the fit may still pass the model-fit test. The leave-one-row-out
  // hypotheses get a chance: a fit that passes is replaced by the
  // hypothesis' fit when that explains the readings better (start_score,
  // solver/calibration/start_selection.h); a fit that misfits, by the one
  // with the smaller chi-square per degree of freedom (a genuine model
  // misfit stays flagged).
  if (samples.size() > kSmallSetRows) return result;
  StageScope challenge("row hypotheses against the fit", false);
  std::optional<CalibrationResult> candidate = consensus_start(robot, samples, options, false);
  if (!candidate) {
    challenge.finish("kept the fit: no hypothesis to challenge it");
    return result;
  }
  CalibrationResult other = refit_without(robot, samples, options, *candidate);
  if (!other.ok) {
    challenge.finish("kept the fit: the hypothesis' refit failed");
    return result;
  }
  assess_model_fit(other, options);
  auto per_dof = [](const CalibrationResult& r) {
    return r.degrees_of_freedom > 0 ? r.chi_square / r.degrees_of_freedom : std::numeric_limits<double>::infinity();
  };
  const bool take = result.misfit ? per_dof(other) < per_dof(result)
                                  : !other.misfit && better_fit(other, result, options.rejection_threshold_sigma);
  challenge.finish(take ? "kept the hypothesis' fit: it explains the readings better" : "kept the fit");
  if (take) result = std::move(other);
  return result;
}

// The anchors of a least-squares rigid fit from the nominal ones, as a start:
// straight cables have no sag to start and reach their minimum from farther
// away, and least squares keeps every reading in, so a start that a robust
// fit would have bent around one good reading cannot form here.
std::optional<Robot> rigid_start(const Robot& robot, const std::vector<Sample>& samples,
                                 const CalibrationOptions& options) {
  CalibrationOptions rigid = options;
  rigid.cable_model = CableModelKind::kRigid;
  rigid.robust = false;
  rigid.huber_width = 0.0;
  rigid.effects.clear();
  rigid.progress = nullptr;
  const CalibrationResult fit = calibrate_once(robot, samples, rigid);
  if (!fit.ok || !has_anchors(fit)) return std::nullopt;
  return started_at(robot, fit);
}


// Multi-start (solver/calibration/start_selection.h): the fit's own anchors
// when its start could not take every row, then a rigid fit's, each of those
// again from its own anchors when it left rows out; the best fit is kept.
CalibrationResult best_of_starts(const Robot& robot, const std::vector<Sample>& samples,
                                 const CalibrationOptions& options, CalibrationResult best) {
  const double threshold = options.rejection_threshold_sigma;
  StageScope stage("other starts", true, StageScope::Inner::kSummaryOnly);
  int tried = 0;
  std::string kept = "the fit from the nominal anchors";
  auto consider = [&](CalibrationResult other, const char* why) {
    ++tried;
    if (!better_fit(other, best, threshold)) return;
    kept = why;
    other.message += std::string(" (kept from ") + why + ": it fits the readings better than the fit from the "
                     "nominal anchors)";
    best = std::move(other);
  };
  auto with_every_row = [&](const CalibrationResult& fit, const char* why) {
    if (fit.ok && !fit.rejected_samples.empty() && has_anchors(fit)) {
      consider(calibrate_from(started_at(robot, fit), samples, options), why);
    }
  };
  with_every_row(best, "a restart from the fit's own anchors, where every row could be started");
  if (const std::optional<Robot> start = rigid_start(robot, samples, options)) {
    CalibrationResult from_rigid = calibrate_from(*start, samples, options);
    const CalibrationResult from_rigid_kept = from_rigid;
    consider(std::move(from_rigid), "a start at a rigid fit's anchors");
    with_every_row(from_rigid_kept, "a start at a rigid fit's anchors, then its own");
  }
  stage.finish(std::to_string(tried) + " other starts fitted; kept " + kept);
  return best;
}

// A gross error that its row's pose and reference force absorb keeps a
// small residual, so the robust fit never flags its row, though leaving it
// out lowers the chi-square by more than threshold^2 (hidden_gross_errors,
// solver/calibration/row_attribution.h). Each such reading, worst first, is
// left out and the fit redone by least squares; it stays out when the
// refit explains the readings better (start_score: its chi-square drop
// above threshold^2, the likelihood-ratio bar every gross error meets)
// without starting to misfit, and the test starts over. Not on a fit that
// misfits: its large residuals are a missing term's signature.
CalibrationResult leave_out_hidden_errors(const Robot& robot, const std::vector<Sample>& samples,
                                          const CalibrationOptions& options, CalibrationResult result) {
  if (!result.ok || result.misfit || !options.robust || options.cable_model != CableModelKind::kCatenary) {
    return result;
  }
  CalibrationOptions plain = options;
  plain.robust = false;
  const double threshold = options.rejection_threshold_sigma;
  StageScope stage("hidden gross errors: readings a row's pose absorbed", false, StageScope::Inner::kSummaryOnly);
  int tested = 0, left = 0;
  for (std::size_t round = 0; round < samples.size(); ++round) {
    bool changed = false;
    for (const SensorReading& hidden : hidden_gross_errors(robot, options, result, threshold)) {
      ++tested;
      std::vector<SensorReading> out = result.gross_errors;
      out.push_back(hidden);
      CalibrationResult refit =
          calibrate_with_restart(started_at(robot, result), leave_out(samples, out, options.cable_model), plain);
      if (!refit.ok) continue;
      for (const SensorReading& p : refit.left_out_residuals) {
        if (p.row == hidden.row && p.sensor == hidden.sensor && p.cable == hidden.cable) out.back().value = p.value;
      }
      refit.gross_errors = out;
      refit.calibration.rejected = out;
      note_left_out(refit);
      assess_model_fit(refit, options);
      if (refit.misfit || !better_fit(refit, result, threshold)) continue;
      result = std::move(refit);
      changed = true;
      ++left;
      break;
    }
    if (!changed) break;
  }
  stage.finish(std::to_string(tested) + " readings refitted without; " + std::to_string(left) + " left out");
  return result;
}

}  // namespace

CalibrationResult calibrate(const Robot& robot, const std::vector<Sample>& samples, const CalibrationOptions& options) {
  std::vector<CalibrationStage> stages;
  const StageRecorder recorder(stages);
  CalibrationResult result = calibrate_from(robot, samples, options);
  if (options.robust && options.cable_model == CableModelKind::kCatenary && worth_other_starts(result)) {
    // The set the kept fit left out gets its swap test once, at the end.
    result = swap_within_rows(robot, samples, options, best_of_starts(robot, samples, options, std::move(result)));
  }
  result = leave_out_hidden_errors(robot, samples, options, std::move(result));
  settle_groups(result.gross_errors);
  settle_groups(result.calibration.rejected);
  // Once, on the fit kept: the choice among fits above is by the chi-square test alone.
  test_missing_terms(robot, options, result);
  result.noise = noise_components(robot, options, result);
  if (result.refusal == Refusal::kSensorFault) {
    StageScope stage("refusal cause: model terms and noise scales tried", false, StageScope::Inner::kSummaryOnly);
    classify_refusal(robot, samples, options, calibrate_from, result);
    stage.finish(result.refusal == Refusal::kModelMisfit ? "the model: " + result.refusal_evidence
                                                         : "the sensors: " + result.refusal_evidence);
    result.message = (result.refusal == Refusal::kModelMisfit ? "the model does not fit: " + result.refusal_evidence +
                                                                    " (not a sensor fault); "
                                                              : "the robot or its sensors need attention: " +
                                                                    result.refusal_evidence + "; ") +
                     result.message;
  }
  result.stages = std::move(stages);
  return result;
}

}  // namespace cdpr

