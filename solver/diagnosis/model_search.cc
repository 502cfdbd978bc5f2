#include "solver/diagnosis/model_search.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace cdpr {
namespace {

// Pools one fold's held-out evaluation into the total.
void pool(HeldOutEvaluation& total, HeldOutEvaluation&& part) {
  total.chi2 += part.chi2;
  total.expected_chi2 += part.expected_chi2;
  total.chi2_variance += part.chi2_variance;
  total.dof += part.dof;
  total.rejected_samples.insert(total.rejected_samples.end(), part.rejected_samples.begin(), part.rejected_samples.end());
  for (HeldOutPose& pose : part.poses) total.poses.push_back(std::move(pose));
  set_residual_rms(total);
}

// options.fit with the model's effects and no progress of its own.
CalibrationOptions fit_options_of(const DiagnosisOptions& options, const std::vector<Effect>& model) {
  CalibrationOptions fit_options = options.fit;
  fit_options.effects = model;
  fit_options.progress = nullptr;
  return fit_options;
}

}  // namespace

std::string model_text(const std::vector<Effect>& model) {
  std::string text = "catenary";
  for (Effect e : model) text += "+" + std::string(effect_model_name(e));
  return text;
}

std::vector<Effect> with_effect(const std::vector<Effect>& model, Effect e) {
  std::vector<Effect> with;
  for (Effect m : model) {
    if (!effect_contains(e, m)) with.push_back(m);
  }
  with.push_back(e);
  return with;
}

std::optional<Effect> replaced_by(const std::vector<Effect>& model, Effect e) {
  for (Effect m : model) {
    if (effect_contains(e, m)) return m;
  }
  return std::nullopt;
}

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

HeldOutEvaluation cross_validate(const Robot& robot, const std::vector<Sample>& samples,
                                 const DiagnosisOptions& options, const std::vector<Effect>& model) {
  const CalibrationOptions fit_options = fit_options_of(options, model);
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
  return calibrate(robot, samples, fit_options_of(options, model));
}

void report(const DiagnosisOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

std::string domain_violation(const CalibrationResult& fit, std::size_t count) {
  if (!fit.ok) return "cannot be fitted to all samples: " + fit.message;
  for (std::size_t j = fit.effects.size() - count; j < fit.effects.size(); ++j) {
    const FittedEffect& e = fit.effects[j];
    const std::string why = effect_domain_violation(e.effect, e.value, e.sigma);
    if (!why.empty()) return std::string(effect_model_name(e.effect)) + ": " + why;
  }
  return {};
}

}  // namespace cdpr
