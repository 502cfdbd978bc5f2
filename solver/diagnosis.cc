#include "solver/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "solver/fit_comparison.h"
#include "solver/held_out_comparison.h"

namespace cdpr {
namespace {

std::string model_text(const std::vector<Effect>& model) {
  std::string text = "catenary";
  for (Effect e : model) text += "+" + std::string(effect_model_name(e));
  return text;
}

// The model with effect e added; e replaces a narrower effect it contains
// (load_cell replaces load_cell_bias: the gain is then the addition).
std::vector<Effect> with_effect(const std::vector<Effect>& model, Effect e) {
  std::vector<Effect> with;
  for (Effect m : model) {
    if (!effect_contains(e, m)) with.push_back(m);
  }
  with.push_back(e);
  return with;
}

// The effect of the model that e replaces when added, if any.
std::optional<Effect> replaced_by(const std::vector<Effect>& model, Effect e) {
  for (Effect m : model) {
    if (effect_contains(e, m)) return m;
  }
  return std::nullopt;
}

// Whether adding e to the model would add anything: not when the model has it
// or an effect that contains it.
bool can_add(const std::vector<Effect>& model, Effect e) {
  return std::none_of(model.begin(), model.end(), [e](Effect m) { return m == e || effect_contains(m, e); });
}

std::string fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

std::string scientific(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.2g", value);
  return buffer;
}

// Pools one fold's held-out evaluation into the total.
void pool(HeldOutEvaluation& total, HeldOutEvaluation&& part) {
  const double n_total = static_cast<double>(total.poses.size()), n_part = static_cast<double>(part.poses.size());
  const auto mean_square = [&](double a, double b) {
    return std::sqrt((a * a * n_total + b * b * n_part) / std::max(1.0, n_total + n_part));
  };
  total.rms_encoder_m = mean_square(total.rms_encoder_m, part.rms_encoder_m);
  total.rms_height_m = mean_square(total.rms_height_m, part.rms_height_m);
  total.rms_force_n = mean_square(total.rms_force_n, part.rms_force_n);
  total.chi2 += part.chi2;
  total.expected_chi2 += part.expected_chi2;
  total.dof += part.dof;
  total.rejected_samples.insert(total.rejected_samples.end(), part.rejected_samples.begin(), part.rejected_samples.end());
  for (HeldOutPose& pose : part.poses) total.poses.push_back(std::move(pose));
}

// Cross-validated held-out evaluation of one model; `ok` false with the
// first failure's reason.
HeldOutEvaluation cross_validate(const Robot& robot, const std::vector<Sample>& samples,
                                 const DiagnosisOptions& options, const std::vector<Effect>& model) {
  CalibrationOptions fit_options = options.fit;
  fit_options.effects = model;
  fit_options.progress = nullptr;
  HeldOutEvaluation total;
  total.ok = true;
  for (int fold = 0; fold < options.folds; ++fold) {
    std::vector<Sample> training, held_out;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      (static_cast<int>(k % options.folds) == fold ? held_out : training).push_back(samples[k]);
    }
    const CalibrationResult fit = calibrate(robot, training, fit_options);
    if (!fit.ok) {
      total.ok = false;
      total.message = "fold " + std::to_string(fold) + ": training fit failed: " + fit.message;
      return total;
    }
    HeldOutEvaluation part = evaluate_held_out(robot, held_out, fit_options, fit);
    if (!part.ok) {
      total.ok = false;
      total.message = "fold " + std::to_string(fold) + ": " + part.message;
      return total;
    }
    pool(total, std::move(part));
  }
  return total;
}

CalibrationResult fit_all(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options,
                          const std::vector<Effect>& model) {
  CalibrationOptions fit_options = options.fit;
  fit_options.effects = model;
  fit_options.progress = nullptr;
  return calibrate(robot, samples, fit_options);
}

void report(const DiagnosisOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

// Why the last `count` effects of a fit on all samples are unphysical, or empty.
std::string domain_violation(const CalibrationResult& fit, std::size_t count) {
  if (!fit.ok) return "cannot be fitted to all samples: " + fit.message;
  for (std::size_t j = fit.effects.size() - count; j < fit.effects.size(); ++j) {
    const FittedEffect& e = fit.effects[j];
    const std::string why = effect_domain_violation(e.effect, e.value, e.sigma);
    if (!why.empty()) return std::string(effect_model_name(e.effect)) + ": " + why;
  }
  return {};
}

struct PairChoice {
  std::size_t first = 0, second = 0;  // indices into the round's candidates, first the better ranked
  HeldOutEvaluation held_out;
  CalibrationResult fit;
  HeldOutComparison against_best;
  FitComparison over_first;  // the second term on top of the first, on all samples
  double level = 0.0;
};

// The pair of the round's individually significant candidates (`strong`,
// best first, strong[0] the best single; `single_fits` their fits
// on all samples) without the best single that predicts the held-out poses
// better than the best single (`best_single`) by the largest drop, if each of its two terms is
// significant on top of the other (likelihood ratio on all samples at alpha
// over the number of pairs) and both fitted values are physical. Two effects
// can each be mimicked in part by a third (a cable elasticity and a load-cell
// bias together look much like a cable density error), and then the greedy
// single step takes the mimic and neither true effect is significant on top
// of it. A pair with the best single (or another form of it) is what the
// greedy steps try anyway, with every candidate for the second step rather
// than the strong ones only. Replacing a well-supported single by a pair
// needs more than a positive held-out drop against it, which noise gives
// half the time: the drop's paired t must be significant too (at alpha over
// the pairs), as the two models are not nested.
std::optional<PairChoice> best_pair(const Robot& robot, const std::vector<Sample>& samples,
                                    const DiagnosisOptions& options, const std::vector<Effect>& model,
                                    const std::vector<Effect>& candidates, const std::vector<std::size_t>& strong,
                                    const std::vector<CalibrationResult>& single_fits,
                                    const HeldOutEvaluation& best_single) {
  const auto same_term = [](Effect x, Effect y) { return x == y || effect_contains(x, y) || effect_contains(y, x); };
  const Effect leader = candidates[strong.front()];
  // Pairs of two different terms, neither a form of the best single.
  std::vector<std::pair<std::size_t, std::size_t>> eligible;
  for (std::size_t a = 1; a < strong.size(); ++a) {
    for (std::size_t b = a + 1; b < strong.size(); ++b) {
      const Effect first = candidates[strong[a]], second = candidates[strong[b]];
      if (!same_term(first, second) && !same_term(first, leader) && !same_term(second, leader)) {
        eligible.emplace_back(a, b);
      }
    }
  }
  if (eligible.empty()) return std::nullopt;
  const double level = options.alpha / static_cast<double>(eligible.size());
  std::optional<PairChoice> best;
  for (const auto& [a, b] : eligible) {
    const Effect first = candidates[strong[a]], second = candidates[strong[b]];
    const std::vector<Effect> with = with_effect(with_effect(model, first), second);
    HeldOutEvaluation f = cross_validate(robot, samples, options, with);
    if (!f.ok) continue;
    const HeldOutComparison c = compare_held_out(best_single, f);
    CalibrationResult fit = fit_all(robot, samples, options, with);
    const FitComparison over_first = compare_fits(single_fits[strong[a]], fit);
    const FitComparison over_second = compare_fits(single_fits[strong[b]], fit);
    report(options, "  try pair " + std::string(effect_model_name(first)) + " + " +
                        std::string(effect_model_name(second)) + ": held-out chi2 drop " + fixed(c.drop, 1) +
                        " against the best single; on all samples p " + scientific(over_first.p_value) +
                        " over " + std::string(effect_model_name(first)) + " alone, p " +
                        scientific(over_second.p_value) + " over " + std::string(effect_model_name(second)) +
                        " alone; held-out paired t " + fixed(c.t_statistic, 2) + ", p " +
                        scientific(normal_upper_tail(c.t_statistic)) + " (each needs < " + scientific(level) + ")");
    if (normal_upper_tail(c.t_statistic) >= level || 2 * c.paired_poses < static_cast<int>(best_single.poses.size())) {
      continue;
    }
    if (!over_first.comparable || !over_second.comparable || over_first.p_value >= level ||
        over_second.p_value >= level) {
      continue;
    }
    if (best && c.drop <= best->against_best.drop) continue;
    if (const std::string why = domain_violation(fit, 2); !why.empty()) {
      report(options, "  reject pair: " + why);
      continue;
    }
    best = PairChoice{strong[a], strong[b], std::move(f), std::move(fit), c, over_first, level};
  }
  return best;
}

}  // namespace

Diagnosis diagnose(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options) {
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

  std::vector<Effect> model = options.fit.effects;
  CalibrationResult start_fit = fit_all(robot, samples, options, model);
  HeldOutEvaluation start = start_fit.ok ? cross_validate(robot, samples, options, model) : HeldOutEvaluation{};
  if (!start_fit.ok || !start.ok) {
    d.message = "the starting model " + model_text(model) + " could not be fitted: " +
                (start_fit.ok ? start.message : start_fit.message);
    return d;
  }
  report(options, "fit " + model_text(model) + ": held-out chi2 " + fixed(start.chi2, 1) + ", expected " +
                      fixed(start.expected_chi2, 1) + ", normalized rms " + fixed(start.normalized_rms(), 3));
  d.steps.push_back({model, Effect::kElasticity, std::move(start_fit), std::move(start), {}, std::nullopt});

  while (static_cast<int>(d.steps.size()) - 1 < options.max_added) {
    std::vector<Effect> untried;
    for (Effect e : options.candidates) {
      if (can_add(model, e)) untried.push_back(e);
    }
    if (untried.empty()) break;
    const double level = options.alpha / static_cast<double>(untried.size());
    std::vector<CandidateScore> scores;
    std::vector<HeldOutEvaluation> evaluations;
    std::vector<CalibrationResult> fits;  // on all samples
    for (Effect e : untried) {
      const std::vector<Effect> with = with_effect(model, e);
      HeldOutEvaluation f = cross_validate(robot, samples, options, with);
      CalibrationResult fit = f.ok ? fit_all(robot, samples, options, with) : CalibrationResult{};
      CandidateScore score;
      score.effect = e;
      score.level = level;
      const FitComparison lr = compare_fits(d.steps.back().fit, fit);
      if (!f.ok) {
        score.failure = f.message;
      } else if (const HeldOutComparison c = compare_held_out(d.steps.back().held_out, f);
                 2 * c.paired_poses < static_cast<int>(d.steps.back().held_out.poses.size())) {
        score.failure = "not comparable: only " + std::to_string(c.paired_poses) +
                        " held-out poses could be evaluated under both models";
      } else if (!lr.comparable) {
        score.failure = "not comparable on all samples: " + (fit.ok ? lr.why_not : fit.message);
      } else {
        score.evaluated = true;
        score.held_out_chi2 = f.chi2;
        score.held_out_drop = c.drop;
        score.t_statistic = c.t_statistic;
        score.fit_chi2_drop = lr.chi2_drop;
        score.fit_p_value = lr.p_value;
        score.added_parameters = lr.added_parameters;
        score.significant = score.held_out_drop > 0.0 && score.fit_p_value < level;
      }
      report(options, "  try " + std::string(effect_model_name(e)) + ": " +
                          (score.evaluated ? "held-out chi2 drop " + fixed(score.held_out_drop, 1) + " (paired t " +
                                                 fixed(score.t_statistic, 2) + "), on all samples " +
                                                 fixed(score.fit_chi2_drop, 1) + ", p " +
                                                 scientific(score.fit_p_value) + " (needs a positive held-out " +
                                                 "drop and p < " + scientific(level) + ")"
                                           : score.failure));
      scores.push_back(score);
      evaluations.push_back(std::move(f));
      fits.push_back(std::move(fit));
    }
    // Best first: significant before not, then by the information criterion
    // on all samples (less noisy than the held-out drop, whose noise is
    // twice its signal: ties between a term and its mimic went either way).
    std::vector<std::size_t> order(scores.size());
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      if (scores[a].evaluated != scores[b].evaluated) return scores[a].evaluated;
      if (scores[a].significant != scores[b].significant) return scores[a].significant;
      return scores[a].aic_gain() > scores[b].aic_gain();
    });
    // The best significant candidate whose fit on all samples is physical.
    std::optional<std::size_t> best;
    for (std::size_t j : order) {
      if (!scores[j].significant) break;
      const std::string why = domain_violation(fits[j], 1);
      if (why.empty()) {
        best = j;
        break;
      }
      scores[j].significant = false;
      scores[j].failure = "rejected: " + why;
      report(options, "  reject " + std::string(effect_model_name(scores[j].effect)) + ": " + why);
    }
    for (std::size_t j : order) d.steps.back().candidates.push_back(scores[j]);
    if (!best) break;

    if (options.try_pairs && static_cast<int>(d.steps.size()) + 1 <= options.max_added) {
      // Still significant: passed both tests and not rejected as unphysical.
      std::vector<std::size_t> strong;
      for (std::size_t j : order) {
        if (scores[j].significant) strong.push_back(j);
      }
      if (std::optional<PairChoice> pair =
              best_pair(robot, samples, options, model, untried, strong, fits, evaluations[*best])) {
        // Two steps, so that each effect is named with the misfit it removes.
        const Effect first = untried[pair->first], second = untried[pair->second];
        const std::optional<Effect> first_replaced = replaced_by(model, first);
        model = with_effect(model, first);
        report(options, "add pair " + std::string(effect_model_name(first)) + " + " +
                            std::string(effect_model_name(second)) + ": held-out normalized rms " +
                            fixed(d.steps.back().held_out.normalized_rms(), 3) + " -> " +
                            fixed(pair->held_out.normalized_rms(), 3) + " (best single " +
                            std::string(effect_model_name(scores[*best].effect)) + ": " +
                            fixed(evaluations[*best].normalized_rms(), 3) + ")");
        CandidateScore then;
        then.effect = second;
        then.evaluated = true;
        then.held_out_chi2 = pair->held_out.chi2;
        const HeldOutComparison c = compare_held_out(evaluations[pair->first], pair->held_out);
        then.held_out_drop = c.drop;
        then.t_statistic = c.t_statistic;
        then.fit_chi2_drop = pair->over_first.chi2_drop;
        then.fit_p_value = pair->over_first.p_value;
        then.level = pair->level;
        then.significant = true;
        d.steps.push_back(
            {model, first, std::move(fits[pair->first]), std::move(evaluations[pair->first]), {then}, first_replaced});
        const std::optional<Effect> second_replaced = replaced_by(model, second);
        model = with_effect(model, second);
        d.steps.push_back({model, second, std::move(pair->fit), std::move(pair->held_out), {}, second_replaced});
        continue;
      }
    }

    const std::optional<Effect> replaced = replaced_by(model, scores[*best].effect);
    model = with_effect(model, scores[*best].effect);
    report(options, "add " + std::string(effect_model_name(scores[*best].effect)) + ": held-out normalized rms " +
                        fixed(d.steps.back().held_out.normalized_rms(), 3) + " -> " +
                        fixed(evaluations[*best].normalized_rms(), 3));
    d.steps.push_back(
        {model, scores[*best].effect, std::move(fits[*best]), std::move(evaluations[*best]), {}, replaced});
  }

  // Backward: drop the added term least needed with everything else in the
  // model while the likelihood ratio for keeping it is not significant at
  // alpha. A mimic taken first (a density error for an elasticity and a
  // load-cell bias) stays beside the true terms the later rounds add.
  while (true) {
    std::optional<std::size_t> weakest;
    CalibrationResult weakest_fit;
    double weakest_p = options.alpha;
    for (std::size_t j = 0; j < model.size(); ++j) {
      if (std::find(options.fit.effects.begin(), options.fit.effects.end(), model[j]) != options.fit.effects.end()) {
        continue;  // the starting model stays
      }
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
    if (!weakest) break;
    std::vector<Effect> without = model;
    without.erase(without.begin() + static_cast<std::ptrdiff_t>(*weakest));
    HeldOutEvaluation f = cross_validate(robot, samples, options, without);
    if (!f.ok) break;
    const Effect dropped = model[*weakest];
    report(options, "remove " + std::string(effect_model_name(dropped)) +
                        ": not significant with the rest of the model (p " + scientific(weakest_p) + ")");
    model = without;
    DiagnosisStep step{model, dropped, std::move(weakest_fit), std::move(f), {}, std::nullopt};
    step.removed = true;
    d.steps.push_back(std::move(step));
  }

  // Back to the narrower form of a term whose extra parameters are not
  // significant with everything else in the model.
  for (Effect narrow : kAllEffects) {
    const auto wide = std::find_if(model.begin(), model.end(), [narrow](Effect m) { return effect_contains(m, narrow); });
    if (wide == model.end()) continue;
    const Effect was = *wide;
    std::vector<Effect> narrowed = model;
    narrowed[static_cast<std::size_t>(wide - model.begin())] = narrow;
    CalibrationResult fit = fit_all(robot, samples, options, narrowed);
    const FitComparison lr = compare_fits(fit, d.steps.back().fit);
    if (!lr.comparable || lr.p_value < options.alpha) continue;
    HeldOutEvaluation f = cross_validate(robot, samples, options, narrowed);
    if (!f.ok) continue;
    report(options, "narrow " + std::string(effect_model_name(was)) + " to " + std::string(effect_model_name(narrow)) +
                        ": its extra parameters are not significant (p " + scientific(lr.p_value) + ")");
    model = narrowed;
    d.steps.push_back({model, narrow, std::move(fit), std::move(f), {}, was});
  }

  const HeldOutEvaluation& last = d.steps.back().held_out;
  // The excess over the expected chi2 as a chi-square(dof) scaled to that mean.
  d.structure_p_value = chi_square_upper_tail(last.chi2 * last.dof / last.expected_chi2, last.dof);
  d.structure_remains = last.normalized_rms() > options.structure_ratio && d.structure_p_value < options.alpha;
  report(options, d.structure_remains ? "structure remains that no known effect explains"
                                      : "no structure left above the noise");

  d.final_fit = d.steps.back().fit;
  d.ok = true;
  return d;
}

}  // namespace cdpr
