#include "solver/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cdpr {
namespace {

double normal_upper_tail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

// z with P(Z > z) = p, by bisection (monotone, no need for speed here).
double normal_upper_quantile(double p) {
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (normal_upper_tail(mid) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::string model_text(const std::vector<Effect>& model) {
  std::string text = "catenary";
  for (Effect e : model) text += "+" + std::string(effect_model_name(e));
  return text;
}

std::string fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

struct Fitted {
  CalibrationResult fit;
  HeldOutEvaluation held_out;
};

Fitted fit_and_evaluate(const Robot& robot, const Diagnosis& d, const DiagnosisOptions& options,
                        const std::vector<Effect>& model) {
  CalibrationOptions fit_options = options.fit;
  fit_options.effects = model;
  fit_options.progress = nullptr;
  Fitted f;
  f.fit = calibrate(robot, d.training, fit_options);
  if (f.fit.ok) f.held_out = evaluate_held_out(robot, d.held_out, fit_options, f.fit);
  return f;
}

void report(const DiagnosisOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

}  // namespace

double chi_square_upper_tail(double x, int k) {
  if (k <= 0) return x > 0.0 ? 0.0 : 1.0;
  if (x <= 0.0) return 1.0;
  const double s = 2.0 / (9.0 * k);
  return normal_upper_tail((std::cbrt(x / k) - (1.0 - s)) / std::sqrt(s));
}

double chi_square_upper_quantile(double p, int k) {
  const double s = 2.0 / (9.0 * k);
  const double root = 1.0 - s + normal_upper_quantile(p) * std::sqrt(s);
  return k * root * root * root;
}

Diagnosis diagnose(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options) {
  Diagnosis d;
  if (options.holdout_every < 2) {
    d.message = "holdout_every must be at least 2";
    return d;
  }
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const bool hold = static_cast<int>(k % options.holdout_every) == options.holdout_every - 1;
    (hold ? d.held_out : d.training).push_back(samples[k]);
  }
  report(options, "split: " + std::to_string(d.training.size()) + " training poses, " +
                      std::to_string(d.held_out.size()) + " held out (one in every " +
                      std::to_string(options.holdout_every) + ")");

  std::vector<Effect> model = options.fit.effects;
  Fitted current = fit_and_evaluate(robot, d, options, model);
  if (!current.fit.ok || !current.held_out.ok) {
    d.message = "the starting model " + model_text(model) + " could not be fitted: " +
                (current.fit.ok ? current.held_out.message : current.fit.message);
    return d;
  }
  report(options, "fit " + model_text(model) + ": held-out chi2 " + fixed(current.held_out.chi2, 1) + ", expected " +
                      fixed(current.held_out.expected_chi2, 1) + ", normalized rms " +
                      fixed(current.held_out.normalized_rms(), 3));
  d.steps.push_back({model, Effect::kElasticity, current.fit, current.held_out, {}});

  while (static_cast<int>(d.steps.size()) - 1 < options.max_added) {
    std::vector<Effect> untried;
    for (Effect e : options.candidates) {
      if (std::find(model.begin(), model.end(), e) == model.end()) untried.push_back(e);
    }
    if (untried.empty()) break;
    const double level = options.alpha / static_cast<double>(untried.size());
    std::vector<CandidateScore> scores;
    std::vector<Fitted> fits;
    for (Effect e : untried) {
      std::vector<Effect> with = model;
      with.push_back(e);
      Fitted f = fit_and_evaluate(robot, d, options, with);
      CandidateScore score;
      score.effect = e;
      score.threshold = chi_square_upper_quantile(level, effect_dimension(e));
      if (!f.fit.ok) {
        score.failure = "training fit failed: " + f.fit.message;
      } else if (!f.held_out.ok) {
        score.failure = "held-out evaluation failed: " + f.held_out.message;
      } else if (f.held_out.poses.size() != d.steps.back().held_out.poses.size()) {
        score.failure = "not comparable: a different number of held-out poses could be evaluated";
      } else {
        score.evaluated = true;
        score.held_out_chi2 = f.held_out.chi2;
        score.held_out_drop = d.steps.back().held_out.chi2 - f.held_out.chi2;
        score.significant = score.held_out_drop > score.threshold;
      }
      report(options, "  try " + std::string(effect_model_name(e)) + ": " +
                          (score.evaluated ? "held-out chi2 drop " + fixed(score.held_out_drop, 1) + " (needs > " +
                                                 fixed(score.threshold, 1) + ")"
                                           : score.failure));
      scores.push_back(score);
      fits.push_back(std::move(f));
    }
    // Best first: significant before not, then by the held-out drop.
    std::vector<std::size_t> order(scores.size());
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      if (scores[a].evaluated != scores[b].evaluated) return scores[a].evaluated;
      return scores[a].held_out_drop > scores[b].held_out_drop;
    });
    for (std::size_t j : order) d.steps.back().candidates.push_back(scores[j]);
    const std::size_t best = order.front();
    if (!scores[best].significant) break;

    model.push_back(scores[best].effect);
    Fitted& chosen = fits[best];
    report(options, "add " + std::string(effect_model_name(scores[best].effect)) + ": held-out normalized rms " +
                        fixed(d.steps.back().held_out.normalized_rms(), 3) + " -> " +
                        fixed(chosen.held_out.normalized_rms(), 3));
    d.steps.push_back({model, scores[best].effect, std::move(chosen.fit), std::move(chosen.held_out), {}});
  }

  const HeldOutEvaluation& last = d.steps.back().held_out;
  // The excess over the expected chi2 as a chi-square(dof) scaled to that mean.
  d.structure_p_value = chi_square_upper_tail(last.chi2 * last.dof / last.expected_chi2, last.dof);
  d.structure_remains = last.normalized_rms() > options.structure_ratio && d.structure_p_value < options.alpha;
  report(options, d.structure_remains ? "structure remains that no known effect explains"
                                      : "no structure left above the noise");

  CalibrationOptions final_options = options.fit;
  final_options.effects = model;
  final_options.progress = nullptr;
  d.final_fit = calibrate(robot, samples, final_options);
  report(options, "final fit of " + model_text(model) + " on all " + std::to_string(samples.size()) +
                      " samples: " + (d.final_fit.ok ? "ok" : d.final_fit.message));
  d.ok = true;
  return d;
}

}  // namespace cdpr
