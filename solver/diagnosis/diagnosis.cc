#include "solver/diagnosis/diagnosis.h"

#include <algorithm>
#include <cstddef>
#include <optional>
#include <utility>

#include "solver/calibration/gross_errors.h"
#include "solver/calibration/noise_components.h"
#include "solver/diagnosis/fit_comparison.h"
#include "solver/diagnosis/held_out_comparison.h"
#include "solver/diagnosis/model_search.h"
#include "solver/diagnosis/pair_search.h"

namespace cdpr {
namespace {

// One round: every effect that can still be added, each fitted with the model.
struct Round {
  std::vector<Effect> untried;
  std::vector<CandidateScore> scores;          // per untried effect
  std::vector<HeldOutEvaluation> evaluations;  // cross-validation of the model with it
  std::vector<CalibrationResult> fits;         // the model with it on all samples
  std::vector<std::size_t> order;              // best first
  std::optional<std::size_t> best;             // the best significant candidate with a physical fit
};

// Scores one candidate against the current step: comparable on enough
// held-out poses and on all samples, then significant when its held-out
// chi2 drops and its likelihood ratio is below `level`.
CandidateScore score(Effect e, double level, const DiagnosisStep& current, const HeldOutEvaluation& f,
                     const CalibrationResult& fit) {
  CandidateScore s;
  s.effect = e;
  s.level = level;
  if (!f.ok) {
    s.failure = f.message;
    return s;
  }
  const HeldOutComparison c = compare_held_out(current.held_out, f);
  if (2 * c.paired_poses < static_cast<int>(current.held_out.poses.size())) {
    s.failure = "not comparable: only " + std::to_string(c.paired_poses) +
                " held-out poses could be evaluated under both models";
    return s;
  }
  const FitComparison lr = compare_fits(current.fit, fit);
  if (!lr.comparable) {
    s.failure = "not comparable on all samples: " + (fit.ok ? lr.why_not : fit.message);
    return s;
  }
  s.evaluated = true;
  s.held_out_chi2 = f.chi2;
  s.held_out_drop = c.drop;
  s.t_statistic = c.t_statistic;
  s.fit_chi2_drop = lr.chi2_drop;
  s.fit_p_value = lr.p_value;
  s.added_parameters = lr.added_parameters;
  s.significant = s.held_out_drop > 0.0 && s.fit_p_value < level;
  return s;
}

std::string score_text(const CandidateScore& s) {
  if (!s.evaluated) return s.failure;
  return "held-out chi2 drop " + fixed(s.held_out_drop, 1) + " (paired t " + fixed(s.t_statistic, 2) +
         "), on all samples " + fixed(s.fit_chi2_drop, 1) + ", p " + scientific(s.fit_p_value) +
         " (needs a positive held-out drop and p < " + scientific(s.level) + ")";
}

// Fits and scores every effect that can still be added (Bonferroni: alpha
// over their number) and ranks them.
Round try_candidates(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options,
                     const DiagnosisStep& current, std::size_t noise_candidates) {
  Round r;
  for (Effect e : options.candidates) {
    if (can_add(current.model, e)) r.untried.push_back(e);
  }
  const double level =
      options.alpha / static_cast<double>(std::max<std::size_t>(1, r.untried.size() + noise_candidates));
  for (Effect e : r.untried) {
    const std::vector<Effect> with = with_effect(current.model, e);
    HeldOutEvaluation f = cross_validate(robot, samples, options, with);
    CalibrationResult fit = f.ok ? fit_all(robot, samples, options, with) : CalibrationResult{};
    r.scores.push_back(score(e, level, current, f, fit));
    report(options, "  try " + std::string(effect_model_name(e)) + ": " + score_text(r.scores.back()));
    r.evaluations.push_back(std::move(f));
    r.fits.push_back(std::move(fit));
  }
  // Best first: significant before not, then by the information criterion
  // on all samples (less noisy than the held-out drop, whose noise is twice
  // its signal: ties between a term and its mimic went either way).
  r.order.resize(r.scores.size());
  for (std::size_t j = 0; j < r.order.size(); ++j) r.order[j] = j;
  std::stable_sort(r.order.begin(), r.order.end(), [&](std::size_t a, std::size_t b) {
    const CandidateScore &x = r.scores[a], &y = r.scores[b];
    if (x.evaluated != y.evaluated) return x.evaluated;
    if (x.significant != y.significant) return x.significant;
    return x.aic_gain() > y.aic_gain();
  });
  // A significant candidate whose fit leaves its physical range mimics something else.
  for (std::size_t j : r.order) {
    if (!r.scores[j].significant) break;
    const std::string why = domain_violation(r.fits[j], 1);
    if (why.empty()) {
      r.best = j;
      break;
    }
    r.scores[j].significant = false;
    r.scores[j].failure = "rejected: " + why;
    report(options, "  reject " + std::string(effect_model_name(r.scores[j].effect)) + ": " + why);
  }
  return r;
}

// The step that adds e, with its fit on all samples and cross-validation.
DiagnosisStep adding(const std::vector<Effect>& model, Effect e, CalibrationResult&& fit,
                     HeldOutEvaluation&& held_out) {
  return {with_effect(model, e), e, std::move(fit), std::move(held_out), {}, replaced_by(model, e), false, std::nullopt, 1.0};
}

// Adds the round's pair as two steps, so that each effect is named with the
// misfit it removes; the first step records the second term as its candidate.
void add_pair(Diagnosis& d, Round& r, PairChoice& pair, const DiagnosisOptions& options) {
  const Effect first = r.untried[pair.first], second = r.untried[pair.second];
  report(options, "add pair " + std::string(effect_model_name(first)) + " + " + std::string(effect_model_name(second)) +
                      ": held-out normalized rms " + fixed(d.steps.back().held_out.normalized_rms(), 3) + " -> " +
                      fixed(pair.held_out.normalized_rms(), 3) + " (best single " +
                      std::string(effect_model_name(r.scores[*r.best].effect)) + ": " +
                      fixed(r.evaluations[*r.best].normalized_rms(), 3) + ")");
  CandidateScore then;
  then.effect = second;
  then.evaluated = true;
  then.held_out_chi2 = pair.held_out.chi2;
  const HeldOutComparison c = compare_held_out(r.evaluations[pair.first], pair.held_out);
  then.held_out_drop = c.drop;
  then.t_statistic = c.t_statistic;
  then.fit_chi2_drop = pair.over_first.chi2_drop;
  then.fit_p_value = pair.over_first.p_value;
  then.level = pair.level;
  then.significant = true;
  DiagnosisStep step =
      adding(d.steps.back().model, first, std::move(r.fits[pair.first]), std::move(r.evaluations[pair.first]));
  step.candidates.push_back(then);
  d.steps.push_back(std::move(step));
  d.steps.push_back(adding(d.steps.back().model, second, std::move(pair.fit), std::move(pair.held_out)));
}

// What the fits of the workflow see: the data with the stated sigmas as the
// noise steps have scaled them so far.
struct Data {
  Robot robot;
  std::vector<Sample> samples;
  DiagnosisOptions options;
};

// The sensor groups a noise step may still scale: those the current fit
// measured, each once.
std::vector<NoiseComponent> noise_untried(const Diagnosis& d) {
  std::vector<NoiseComponent> out;
  for (const NoiseComponent& c : d.steps.back().fit.noise) {
    if (std::none_of(d.noise.begin(), d.noise.end(), [&](const NoiseFinding& f) { return f.group == c.group; })) {
      out.push_back(c);
    }
  }
  return out;
}

// A noise candidate scored from the current fit's variance components: the
// likelihood ratio of scaling the group's sigma, at the round's level. Only
// a group noisier than stated is a finding (a sigma stated too large widens
// the anchors' sigmas but does not bias them).
CandidateScore noise_score(const NoiseComponent& c, double level) {
  CandidateScore s;
  s.noise = c.group;
  s.noise_scale = c.scale;
  s.evaluated = true;
  s.fit_chi2_drop = c.likelihood_gain;
  s.fit_p_value = chi_square_upper_tail(c.likelihood_gain, 1);
  s.added_parameters = 1;
  s.level = level;
  s.significant = c.scale > 1.0 && s.fit_p_value < level;
  return s;
}

std::string noise_text(NoiseGroup group, double scale) {
  return std::string(noise_group_description(group)) + " " + fixed(scale, 2) + "x robot.toml";
}

// The step that scales `c`'s group by its implied factor: the data change
// for every later fit. False (nothing changed) when the scaled model cannot
// be fitted or cross-validated.
bool add_noise_step(Diagnosis& d, Data& data, const CandidateScore& c) {
  Data scaled = data;
  scale_noise(*c.noise, c.noise_scale, scaled.robot, scaled.samples, scaled.options.fit);
  const std::vector<Effect> model = d.steps.back().model;
  CalibrationResult fit = fit_all(scaled.robot, scaled.samples, scaled.options, model);
  HeldOutEvaluation f = fit.ok ? cross_validate(scaled.robot, scaled.samples, scaled.options, model) : HeldOutEvaluation{};
  if (!fit.ok || !f.ok) {
    report(data.options, "  cannot scale " + noise_text(*c.noise, c.noise_scale) + ": " +
                             (fit.ok ? f.message : fit.message));
    return false;
  }
  report(data.options, "add " + noise_text(*c.noise, c.noise_scale) + ": held-out normalized rms " +
                           fixed(d.steps.back().held_out.normalized_rms(), 3) + " -> " + fixed(f.normalized_rms(), 3));
  DiagnosisStep step{model, Effect::kElasticity, std::move(fit), std::move(f), {}, std::nullopt, false, std::nullopt,
                     1.0};
  step.noise = c.noise;
  step.noise_scale = c.noise_scale;
  d.steps.push_back(std::move(step));
  d.noise.push_back({*c.noise, c.noise_scale});
  data = std::move(scaled);
  return true;
}

// The mimic set of the step about to take `taken` (a term of the round, or
// a noise score): every other evaluated candidate with a physical fit whose
// Akaike gain is within kMimicAicMargin of the taken one's. Recorded only
// when it has more than one member.
void record_mimics(Diagnosis& d, const Round& r, const std::vector<CandidateScore>& noise_scores,
                   const CandidateScore& taken) {
  MimicSet set;
  set.step = d.steps.size();
  auto member = [&](const CandidateScore& c, const CalibrationResult* fit) {
    MimicMember m{c.effect, c.noise, c.noise_scale, taken.aic_gain() - c.aic_gain(), {},
                  fit ? fit->calibration : d.steps.back().fit.calibration};
    if (fit && !c.noise) {
      for (const std::string& name : effect_value_names(c.effect)) {
        for (const std::string& key : {name, name + "_sigma"}) {
          const auto v = fit->calibration.effects.find(key);
          if (v != fit->calibration.effects.end()) m.values[key] = v->second;
        }
      }
    }
    return m;
  };
  auto close = [&](const CandidateScore& c) {
    return c.evaluated && c.failure.empty() && taken.aic_gain() - c.aic_gain() <= kMimicAicMargin;
  };
  const bool taken_is_noise = taken.noise.has_value();
  for (std::size_t j = 0; j < r.scores.size(); ++j) {
    const bool is_taken = !taken_is_noise && r.scores[j].effect == taken.effect;
    if (is_taken) set.members.insert(set.members.begin(), member(r.scores[j], &r.fits[j]));
    else if (close(r.scores[j])) set.members.push_back(member(r.scores[j], &r.fits[j]));
  }
  for (const CandidateScore& n : noise_scores) {
    const bool is_taken = taken_is_noise && n.noise == taken.noise;
    if (is_taken) set.members.insert(set.members.begin(), member(n, nullptr));
    else if (n.noise_scale > 1.0 && close(n)) set.members.push_back(member(n, nullptr));
  }
  std::stable_sort(set.members.begin() + 1, set.members.end(),
                   [](const MimicMember& a, const MimicMember& b) { return a.aic_gap < b.aic_gap; });
  if (set.members.size() > 1) d.mimic_sets.push_back(std::move(set));
}

// Forward: adds the best significant candidate (or a pair, or a noise
// scale) while one is significant and fewer than options.max_added were
// added. Terms and noise scales are ranked by the same criterion (Akaike's
// on all samples); a noise scale is added alone.
void add_significant_effects(Diagnosis& d, Data& data) {
  const Robot& robot = data.robot;
  const std::vector<Sample>& samples = data.samples;
  const DiagnosisOptions& options = data.options;
  while (static_cast<int>(d.steps.size()) - 1 < options.max_added) {
    const std::vector<NoiseComponent> noisy = noise_untried(d);
    Round r = try_candidates(robot, samples, options, d.steps.back(), noisy.size());
    const double level =
        options.alpha / static_cast<double>(std::max<std::size_t>(1, r.untried.size() + noisy.size()));
    std::optional<CandidateScore> noise;
    std::vector<CandidateScore> noise_scores;
    for (const NoiseComponent& c : noisy) {
      noise_scores.push_back(noise_score(c, level));
      const CandidateScore& n = noise_scores.back();
      report(options, "  try " + noise_text(c.group, c.scale) + ": -2 log L drop " + fixed(n.fit_chi2_drop, 1) +
                          ", p " + scientific(n.fit_p_value) + " (needs p < " + scientific(level) + ")");
      if (n.significant && (!noise || n.aic_gain() > noise->aic_gain())) noise = n;
    }
    for (std::size_t j : r.order) d.steps.back().candidates.push_back(r.scores[j]);
    for (const CandidateScore& n : noise_scores) d.steps.back().candidates.push_back(n);
    const bool noise_first = noise && (!r.best || noise->aic_gain() > r.scores[*r.best].aic_gain());
    if (noise_first) {
      const std::size_t sets = d.mimic_sets.size();
      record_mimics(d, r, noise_scores, *noise);
      if (add_noise_step(d, data, *noise)) continue;
      d.mimic_sets.resize(sets);
      if (!r.best) return;
    }
    if (!r.best) return;

    if (options.try_pairs && static_cast<int>(d.steps.size()) + 1 <= options.max_added) {
      // Still significant: passed both tests and not rejected as unphysical.
      std::vector<std::size_t> strong;
      for (std::size_t j : r.order) {
        if (r.scores[j].significant) strong.push_back(j);
      }
      if (std::optional<PairChoice> pair = best_pair(robot, samples, options, d.steps.back().model, r.untried, strong,
                                                     r.fits, r.evaluations[*r.best])) {
        add_pair(d, r, *pair, options);
        continue;
      }
    }
    const Effect e = r.scores[*r.best].effect;
    record_mimics(d, r, noise_scores, r.scores[*r.best]);
    report(options, "add " + std::string(effect_model_name(e)) + ": held-out normalized rms " +
                        fixed(d.steps.back().held_out.normalized_rms(), 3) + " -> " +
                        fixed(r.evaluations[*r.best].normalized_rms(), 3));
    d.steps.push_back(adding(d.steps.back().model, e, std::move(r.fits[*r.best]), std::move(r.evaluations[*r.best])));
  }
}

// Backward: drops the added term least needed with everything else in the
// model while the likelihood ratio for keeping it is not significant at
// alpha. A mimic taken first (a density error for an elasticity and a
// load-cell bias) stays beside the true terms the later rounds add.
void remove_unneeded_effects(Diagnosis& d, const Robot& robot, const std::vector<Sample>& samples,
                             const DiagnosisOptions& options) {
  const std::vector<Effect>& start = options.fit.effects;
  while (true) {
    const std::vector<Effect> model = d.steps.back().model;
    std::optional<std::size_t> weakest;
    CalibrationResult weakest_fit;
    double weakest_p = options.alpha;
    for (std::size_t j = 0; j < model.size(); ++j) {
      if (std::find(start.begin(), start.end(), model[j]) != start.end()) continue;  // the starting model stays
      std::vector<Effect> without = model;
      without.erase(without.begin() + static_cast<std::ptrdiff_t>(j));
      CalibrationResult fit = fit_all(robot, samples, options, without);
      const FitComparison lr = compare_fits(fit, d.steps.back().fit);
      if (lr.comparable && lr.p_value >= weakest_p) {
        weakest = j;
        weakest_p = lr.p_value;
        weakest_fit = std::move(fit);
      }
    }
    if (!weakest) return;
    std::vector<Effect> without = model;
    without.erase(without.begin() + static_cast<std::ptrdiff_t>(*weakest));
    HeldOutEvaluation f = cross_validate(robot, samples, options, without);
    if (!f.ok) return;
    const Effect dropped = model[*weakest];
    report(options, "remove " + std::string(effect_model_name(dropped)) +
                        ": not significant with the rest of the model (p " + scientific(weakest_p) + ")");
    DiagnosisStep step{without, dropped, std::move(weakest_fit), std::move(f), {}, std::nullopt, false, std::nullopt,
                       1.0};
    step.removed = true;
    d.steps.push_back(std::move(step));
  }
}

// The level a round on top of `model` tests its candidates at: alpha over
// the number of them (Bonferroni).
double round_level(const std::vector<Effect>& model, const DiagnosisOptions& options) {
  const auto untried = std::count_if(options.candidates.begin(), options.candidates.end(),
                                     [&](Effect e) { return can_add(model, e); });
  return options.alpha / static_cast<double>(std::max<std::ptrdiff_t>(1, untried));
}

// Back to the narrower form of a term whose extra parameters are not
// significant with everything else in the model: a load-cell gain taken
// while an elasticity was still missing is often no gain once it is there.
// The wide term entered on its narrow part's strength (bias and gain tested
// together), so its extra parameters must pass the bar any term meets to
// enter: a round's level on top of the narrowed model. At alpha alone a gain
// that is only noise would stay in one data set of a hundred.
void narrow_wide_effects(Diagnosis& d, const Robot& robot, const std::vector<Sample>& samples,
                         const DiagnosisOptions& options) {
  for (Effect narrow : kAllEffects) {
    const std::vector<Effect> model = d.steps.back().model;
    const auto wide = std::find_if(model.begin(), model.end(), [narrow](Effect m) { return effect_contains(m, narrow); });
    if (wide == model.end()) continue;
    const Effect was = *wide;
    std::vector<Effect> narrowed = model;
    narrowed[static_cast<std::size_t>(wide - model.begin())] = narrow;
    CalibrationResult fit = fit_all(robot, samples, options, narrowed);
    const FitComparison lr = compare_fits(fit, d.steps.back().fit);
    const double level = round_level(narrowed, options);
    if (!lr.comparable || lr.p_value < level) continue;
    HeldOutEvaluation f = cross_validate(robot, samples, options, narrowed);
    if (!f.ok) continue;
    report(options, "narrow " + std::string(effect_model_name(was)) + " to " + std::string(effect_model_name(narrow)) +
                        ": its extra parameters are not significant (p " + scientific(lr.p_value) + ", needs p < " +
                        scientific(level) + ")");
    d.steps.push_back({narrowed, narrow, std::move(fit), std::move(f), {}, was, false, std::nullopt, 1.0});
  }
}

}  // namespace

namespace {

Diagnosis diagnose_rows(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options);

// Of the starting model's gross errors, those a robust fit of the terms
// found (solver/calibration/calibrate.h) also finds. The judge is the final
// model with every term of its mimic sets: of terms alike on the other
// poses, the one that explains these readings may be the one the workflow
// did not take. It fits every reading (a leave-one-out prediction of a row
// that lost two readings is too loose to judge by).
std::vector<SensorReading> still_gross_errors(const Robot& robot, const std::vector<Sample>& all_samples,
                                              const std::vector<SensorReading>& gross_errors, const Diagnosis& d,
                                              const CalibrationOptions& start) {
  CalibrationOptions judge = start;
  judge.effects = d.steps.back().model;
  for (const MimicSet* set : standing_mimic_sets(d)) {
    for (const MimicMember& m : set->members) {
      if (!m.noise && std::find(judge.effects.begin(), judge.effects.end(), m.effect) == judge.effects.end()) {
        judge.effects.push_back(m.effect);
      }
    }
  }
  // A term another one contains (load_cell_bias in load_cell) goes: they share a parameter.
  std::erase_if(judge.effects, [&](Effect e) {
    return std::any_of(judge.effects.begin(), judge.effects.end(),
                       [&](Effect other) { return other != e && effect_contains(other, e); });
  });
  const CalibrationResult judged = calibrate(robot, all_samples, judge);
  if (!judged.ok) return gross_errors;
  std::vector<SensorReading> standing;
  for (const SensorReading& r : gross_errors) {
    const bool again = std::any_of(judged.gross_errors.begin(), judged.gross_errors.end(), [&](const SensorReading& g) {
      return g.row == r.row && g.sensor == r.sensor && g.cable == r.cable;
    });
    if (again) standing.push_back(r);
  }
  return standing;
}

}  // namespace

Diagnosis diagnose(const Robot& robot, const std::vector<Sample>& all_samples, const DiagnosisOptions& options) {
  if (!options.fit.robust) return diagnose_rows(robot, all_samples, options);
  const CalibrationResult robust = calibrate(robot, all_samples, options.fit);
  const std::vector<Sample> samples = leave_out(all_samples, robust.gross_errors, options.fit.cable_model);
  if (!robust.gross_errors.empty()) {
    report(options, std::to_string(robust.gross_errors.size()) +
                        " readings with gross errors left out (robust fit of the starting model)");
  }
  DiagnosisOptions plain = options;
  plain.fit.robust = false;
  // The workflow judges misfit itself (held-out chi-square against the fits'
  // own uncertainty): sigmas scaled up by the model-fit test would widen
  // that noise floor.
  plain.fit.misfit_alpha = 0.0;
  Diagnosis d = diagnose_rows(robot, samples, plain);
  std::vector<SensorReading> gross_errors = robust.gross_errors;
  // The starting model judged the gross errors without the terms the
  // workflow found. Where a term matters most (a load-cell gain at the
  // highest tensions, the very poses that tell it from a bias) its missing
  // signal looks like gross errors to that model: those the final model
  // explains go back in, and the workflow runs once more on them.
  if (d.ok && !gross_errors.empty() && !d.steps.back().model.empty()) {
    const std::vector<SensorReading> standing = still_gross_errors(robot, all_samples, gross_errors, d, options.fit);
    if (standing.size() < gross_errors.size()) {
      report(options, std::to_string(gross_errors.size() - standing.size()) +
                          " of them explained by the terms found: taken back, diagnosing again");
      Diagnosis again = diagnose_rows(robot, leave_out(all_samples, standing, options.fit.cable_model), plain);
      if (again.ok) {
        d = std::move(again);
        gross_errors = standing;
      }
    }
  }
  d.gross_errors = gross_errors;
  d.final_fit.calibration.rejected = gross_errors;
  d.final_fit.gross_errors = gross_errors;
  return d;
}

std::vector<const MimicSet*> standing_mimic_sets(const Diagnosis& d) {
  std::vector<const MimicSet*> out;
  if (d.steps.empty()) return out;
  const std::vector<Effect>& model = d.steps.back().model;
  for (const MimicSet& set : d.mimic_sets) {
    const bool standing = std::any_of(set.members.begin(), set.members.end(), [&](const MimicMember& m) {
      if (m.noise) {
        return std::any_of(d.noise.begin(), d.noise.end(), [&](const NoiseFinding& f) { return f.group == *m.noise; });
      }
      return std::any_of(model.begin(), model.end(), [&](Effect e) {
        return e == m.effect || effect_contains(e, m.effect) || effect_contains(m.effect, e);
      });
    });
    if (standing) out.push_back(&set);
  }
  return out;
}

namespace {

Diagnosis diagnose_rows(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options) {
  Diagnosis d;
  if (options.folds < 2 || static_cast<std::size_t>(options.folds) > samples.size()) {
    d.message = "need 2 to " + std::to_string(samples.size()) + " cross-validation folds, got " +
                std::to_string(options.folds);
    return d;
  }
  d.sample_count = static_cast<int>(samples.size());
  d.folds = options.folds;
  report(options, std::to_string(samples.size()) + " samples, " + std::to_string(options.folds) +
                      "-fold cross-validation");

  const std::vector<Effect>& model = options.fit.effects;
  CalibrationResult start_fit = fit_all(robot, samples, options, model);
  HeldOutEvaluation start = start_fit.ok ? cross_validate(robot, samples, options, model) : HeldOutEvaluation{};
  if (!start_fit.ok || !start.ok) {
    d.message = "the starting model " + model_text(model) + " could not be fitted: " +
                (start_fit.ok ? start.message : start_fit.message);
    return d;
  }
  report(options, "fit " + model_text(model) + ": held-out chi2 " + fixed(start.chi2, 1) + ", expected " +
                      fixed(start.expected_chi2, 1) + ", normalized rms " + fixed(start.normalized_rms(), 3));
  d.steps.push_back(
      {model, Effect::kElasticity, std::move(start_fit), std::move(start), {}, std::nullopt, false, std::nullopt, 1.0});

  Data data{robot, samples, options};
  add_significant_effects(d, data);
  remove_unneeded_effects(d, data.robot, data.samples, data.options);
  narrow_wide_effects(d, data.robot, data.samples, data.options);

  const HeldOutEvaluation& last = d.steps.back().held_out;
  // A significant excess over what a right model gives is structure,
  // whatever its size: an effect the known terms mimic in part (a wind the
  // CoM, load-cell and encoder-scale terms take up) leaves only a small
  // excess, which a threshold on the rms would call "no structure". The
  // test needs chi2's true spread under a right model
  // (HeldOutEvaluation::chi2_variance): a chi-square's spread understates
  // it and finds structure in data without effects.
  d.structure_p_value = scaled_chi_square_upper_tail(last.chi2, last.expected_chi2, last.chi2_variance);
  d.structure_remains = d.structure_p_value < options.alpha;
  report(options, d.structure_remains ? "structure remains that no known effect explains"
                                      : "no structure left above the noise");

  d.final_fit = d.steps.back().fit;
  d.ok = true;
  return d;
}

}  // namespace

}  // namespace cdpr
