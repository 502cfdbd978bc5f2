#include "diagnosis_report.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "src/report/html.h"
#include "src/report/residual_trends.h"
#include "src/report/sections.h"

namespace cdpr::tools {
namespace {

using report::residual_trends;
using report::Trend;

void append(std::string& out, const char* format, ...) __attribute__((format(printf, 2, 3)));
void append(std::string& out, const char* format, ...) {
  char buffer[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof buffer, format, args);
  va_end(args);
  out += buffer;
}

std::string model_text(const std::vector<Effect>& model) {
  std::string text = "catenary";
  for (Effect e : model) text += " + " + std::string(effect_model_name(e));
  return text;
}

std::string values_text(const EffectValues& values, const std::string& name) {
  std::string text;
  const auto value = values.find(name);
  if (value == values.end()) return "?";
  const auto sigma = values.find(name + "_sigma");
  for (std::size_t j = 0; j < value->second.size(); ++j) {
    append(text, "%s%.4g", j ? ", " : "", value->second[j]);
    if (sigma != values.end() && j < sigma->second.size()) append(text, " +- %.2g", sigma->second[j]);
  }
  return text;
}

// Largest |fitted - true| / sigma over the effect's components; negative when unknown.
double sigma_distance(const EffectValues& fitted, const EffectValues& truth, const std::string& name) {
  const auto value = fitted.find(name), sigma = fitted.find(name + "_sigma"), real = truth.find(name);
  if (value == fitted.end() || sigma == fitted.end()) return -1.0;
  double worst = 0.0;
  for (std::size_t j = 0; j < value->second.size(); ++j) {
    const double t = real == truth.end() ? 0.0 : real->second.at(std::min(j, real->second.size() - 1));
    worst = std::max(worst, std::abs(value->second[j] - t) / sigma->second[j]);
  }
  return worst;
}

double mean_anchor_error(const Calibration& cal, const Truth& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < cal.winches.size() && i < truth.winches.size(); ++i) {
    sum += (cal.winches[i].anchor_world - truth.winches[i].anchor_world).norm();
  }
  return cal.winches.empty() ? 0.0 : sum / static_cast<double>(cal.winches.size());
}

void append_held_out(std::string& out, const HeldOutEvaluation& h) {
  append(out, "  held out: normalized rms %.3f (chi2 %.1f, expected %.1f with dof %d), rms encoder %.4f m, "
              "height %.4f m, force %.2f N\n", h.normalized_rms(), h.chi2, h.expected_chi2, h.dof, h.rms_encoder_m,
         h.rms_height_m, h.rms_force_n);
}

void append_trends(std::string& out, const HeldOutEvaluation& h, int count) {
  const std::vector<Trend> trends = residual_trends(h);
  append(out, "  strongest held-out residual trends:\n");
  for (int k = 0; k < count && k < static_cast<int>(trends.size()); ++k) {
    const Trend& t = trends[k];
    append(out, "    %-10s vs %-22s slope %+.3g %s per unit, r %+.2f, t %+.1f\n", t.sensor.c_str(), t.against.c_str(),
           t.slope, t.unit.c_str(), t.correlation, t.t_statistic);
  }
}

// The effects of the final model that the starting model did not have.
std::vector<Effect> added_effects(const Diagnosis& d) {
  std::vector<Effect> out;
  for (Effect e : d.steps.back().model) {
    if (std::find(d.steps.front().model.begin(), d.steps.front().model.end(), e) == d.steps.front().model.end()) {
      out.push_back(e);
    }
  }
  return out;
}

template <typename... T>
std::string format_text(const char* fmt, T... values) {
  return report::format(fmt, values...);
}

// A candidate's name: the term's, or "orientation noise x2.31" for a noise scale.
std::string candidate_name(const CandidateScore& c) {
  if (!c.noise) return std::string(effect_model_name(c.effect));
  return std::string(noise_group_description(*c.noise)) + format_text(" x%.2f", c.noise_scale);
}

// "load_cell_bias or load_cell: indistinguishable on these poses (Akaike
// gap 0.8); load_cell_bias: force_bias = 12.1 +- 1.3; load_cell: ...".
std::string mimic_text(const MimicSet& set) {
  std::string names, gaps, values;
  for (std::size_t j = 0; j < set.members.size(); ++j) {
    const MimicMember& m = set.members[j];
    names += (j == 0 ? "" : j + 1 == set.members.size() ? " or " : ", ") + mimic_member_name(m);
    if (j > 0) gaps += (gaps.empty() ? "" : ", ") + format_text("%.1f", m.aic_gap);
    std::string v;
    for (const auto& [name, numbers] : m.values) {
      if (name.ends_with("_sigma")) continue;
      v += (v.empty() ? "" : ", ") + name + " = " + values_text(m.values, name);
    }
    values += "; " + mimic_member_name(m) + (v.empty() ? "" : ": " + v);
  }
  return names + ": indistinguishable on these poses (Akaike gap " + gaps + " from the first, within " +
         format_text("%.0f", kMimicAicMargin) + ")" + values;
}

// "load_cell_bias|load_cell;density_error|elasticity", or "none".
std::string mimic_list(const Diagnosis& d) {
  std::string out;
  for (const MimicSet* set : standing_mimic_sets(d)) {
    std::string members;
    for (const MimicMember& m : set->members) {
      members += (members.empty() ? "" : "|") +
                 (m.noise ? std::string(noise_group_name(*m.noise)) + "-noise" : std::string(effect_model_name(m.effect)));
    }
    out += (out.empty() ? "" : ";") + members;
  }
  return out.empty() ? "none" : out;
}

// "orientation-noise-x2.31": a noise step in the conclusion's list.
std::string noise_text_of(const DiagnosisStep& step) {
  std::string name(noise_group_name(*step.noise));
  return name + format_text("-noise-x%.2f", step.noise_scale);
}

// "orientation:2.31,encoder:1.40", or "none": the noise steps' findings.
std::string noise_list(const Diagnosis& d) {
  std::string out;
  for (const NoiseFinding& f : d.noise) {
    out += (out.empty() ? "" : ",") + std::string(noise_group_name(f.group)) + format_text(":%.2f", f.scale);
  }
  return out.empty() ? "none" : out;
}

// "orientation noise 2.31x robot.toml and encoder noise 1.40x robot.toml".
std::string noise_words(const Diagnosis& d) {
  std::string out;
  for (std::size_t j = 0; j < d.noise.size(); ++j) {
    out += (j == 0 ? "" : j + 1 == d.noise.size() ? " and " : ", ") +
           std::string(noise_group_description(d.noise[j].group)) + format_text(" %.2fx robot.toml", d.noise[j].scale);
  }
  return out;
}

// One machine-readable line for scripts (tools/diagnose-acceptance.sh).
void append_summary(std::string& out, const Diagnosis& d, const ReportContext& c) {
  // The terms of the final model beyond the starting one (a term replaced on the way is not named).
  const std::vector<Effect> named = added_effects(d);
  std::string added;
  for (Effect e : named) added += (added.empty() ? "" : ",") + std::string(effect_model_name(e));
  append(out, "summary: added=%s noise=%s mimic=%s structure=%s structure_p=%.2g normalized_rms_start=%.4f "
              "normalized_rms_final=%.4f",
         added.empty() ? "none" : added.c_str(), noise_list(d).c_str(), mimic_list(d).c_str(),
         d.structure_remains ? "remains" : "none",
         d.structure_p_value,
         d.steps.front().held_out.normalized_rms(), d.steps.back().held_out.normalized_rms());
  if (c.truth && d.final_fit.ok) {
    // Of the final fit on all samples: anchors, and the largest |fitted - true| / sigma over the added effects.
    double worst = 0.0;
    for (Effect e : named) {
      for (const std::string& name : effect_value_names(e)) {
        worst = std::max(worst, sigma_distance(d.final_fit.calibration.effects, c.truth->effects, name));
      }
    }
    append(out, " anchor_error_final=%.4f effect_sigma_distance=%.2f", mean_anchor_error(d.final_fit.calibration, *c.truth),
           worst);
  }
  append(out, " gross_errors=%zu\n", d.gross_errors.size());
}

}  // namespace

std::string diagnosis_text(const Diagnosis& d, const ReportContext& c) {
  std::string out;
  append(out, "cdpr-calib diagnose: robot %s, %d samples, %d-fold cross-validation (each pose predicted by a fit "
              "without its fold)\n", c.robot_name.c_str(), d.sample_count, d.folds);
  append(out, "noise: encoder %.4f m, force %.2f N; held-out normalized rms = sqrt(chi2 / expected chi2 of a right "
              "model), 1 at the noise floor\n",
         c.noise.encoder_m, c.noise.force_n);
  if (!d.ok) {
    append(out, "diagnosis failed: %s\nsummary: failed\n", d.message.c_str());
    return out;
  }
  for (std::size_t s = 0; s < d.steps.size(); ++s) {
    const DiagnosisStep& step = d.steps[s];
    append(out, "\nstep %zu: %s\n", s, model_text(step.model).c_str());
    if (s > 0 && step.noise) {
      append(out, "  scaled the sigma of the %s by %.2f: the residuals say it is noisier than robot.toml states\n",
             std::string(noise_group_description(*step.noise)).c_str(), step.noise_scale);
    } else if (s > 0 && step.removed) {
      append(out, "  removed %s: not significant with the rest of the model\n",
             std::string(effect_model_name(step.added)).c_str());
    } else if (s > 0) {
      append(out, "  added %s%s:\n", std::string(effect_model_name(step.added)).c_str(),
             step.replaced ? (" in place of " + std::string(effect_model_name(*step.replaced))).c_str() : "");
      for (const std::string& name : effect_value_names(step.added)) {
        append(out, "    %s = %s\n", name.c_str(), values_text(step.fit.calibration.effects, name).c_str());
        if (!c.truth) continue;
        const auto real = c.truth->effects.find(name);
        append(out, "      truth: %s; fitted value %.1f sigma from it\n",
               real == c.truth->effects.end() ? "not in the data (0)" : values_text(c.truth->effects, name).c_str(),
               sigma_distance(step.fit.calibration.effects, c.truth->effects, name));
      }
    }
    append_held_out(out, step.held_out);
    if (c.truth) append(out, "  mean anchor error against truth: %.4f m\n", mean_anchor_error(step.fit.calibration, *c.truth));
    append_trends(out, step.held_out, 3);
    if (step.candidates.empty()) continue;
    append(out, "  candidates (held-out chi2 drop and the paired t of its per-pose drops; chi2 drop of the fit on all "
                "samples and its likelihood-ratio p; significant: positive held-out drop and p below the level):\n");
    for (const CandidateScore& cand : step.candidates) {
      const std::string name = candidate_name(cand);
      if (!cand.evaluated) {
        append(out, "    %-14s not evaluated: %s\n", name.c_str(), cand.failure.c_str());
      } else if (cand.noise) {
        append(out, "    %-24s  -2 log L drop %9.1f  p %8.2g (level %.2g)%s\n", name.c_str(), cand.fit_chi2_drop,
               cand.fit_p_value, cand.level, cand.significant ? "  significant" : "");
      } else {
        append(out, "    %-14s %10.1f  t %6.2f  all samples %9.1f  p %8.2g (level %.2g)%s\n", name.c_str(),
               cand.held_out_drop, cand.t_statistic, cand.fit_chi2_drop, cand.fit_p_value, cand.level,
               cand.significant ? "  significant" : "");
        if (!cand.failure.empty()) append(out, "      %s\n", cand.failure.c_str());
      }
    }
  }

  const DiagnosisStep& first = d.steps.front();
  const DiagnosisStep& last = d.steps.back();
  append(out, "\nconclusion: ");
  if (d.steps.size() == 1) {
    append(out, "no effect added (none significant on held-out poses)\n");
  } else {
    append(out, "added");
    for (std::size_t s = 1; s < d.steps.size(); ++s) {
      if (d.steps[s].noise) {
        append(out, " %s", noise_text_of(d.steps[s]).c_str());
        continue;
      }
      append(out, " %s%s%s", d.steps[s].removed ? "removed:" : "", std::string(effect_model_name(d.steps[s].added)).c_str(),
             d.steps[s].replaced ? (" (in place of " + std::string(effect_model_name(*d.steps[s].replaced)) + ")").c_str()
                                 : "");
    }
    append(out, "; held-out normalized rms %.3f -> %.3f, encoder rms %.4f -> %.4f m, force rms %.2f -> %.2f N\n",
           first.held_out.normalized_rms(), last.held_out.normalized_rms(), first.held_out.rms_encoder_m,
           last.held_out.rms_encoder_m, first.held_out.rms_force_n, last.held_out.rms_force_n);
  }
  for (const MimicSet* set : standing_mimic_sets(d)) append(out, "MIMICS: %s\n", mimic_text(*set).c_str());
  if (d.structure_remains) {
    append(out, "STRUCTURE REMAINS that no known effect explains: held-out normalized rms %.3f, p = %.2g against the "
                "noise; strongest residual trend: %s\n",
           last.held_out.normalized_rms(), d.structure_p_value,
           report::strongest_trend_text(residual_trends(last.held_out)).c_str());
  } else {
    append(out, "no structure left above the noise (held-out normalized rms %.3f, p = %.2g)\n",
           last.held_out.normalized_rms(), d.structure_p_value);
  }
  if (d.final_fit.ok) {
    append(out, "final model on all samples: %s\n", model_text(last.model).c_str());
    for (Effect e : last.model) {
      for (const std::string& name : effect_value_names(e)) {
        append(out, "  %s = %s\n", name.c_str(), values_text(d.final_fit.calibration.effects, name).c_str());
      }
    }
    if (c.truth) {
      append(out, "  mean anchor error against truth: %.4f m\n", mean_anchor_error(d.final_fit.calibration, *c.truth));
    }
  } else {
    append(out, "final fit on all samples failed: %s\n", d.final_fit.message.c_str());
  }
  if (!d.gross_errors.empty()) {
    append(out, "rows left out as gross errors (robust fit of the starting model; not an effect):\n");
    for (const SensorReading& r : d.gross_errors) {
      append(out, "  row %d %s%s: %+.1f sigma\n", r.row, sensor_name(r.sensor),
             r.sensor == SensorKind::kEncoder ? (" cable " + std::to_string(r.cable)).c_str() : "", r.value);
    }
  }
  append_summary(out, d, c);
  return out;
}

namespace {

std::string effect_list(const std::vector<Effect>& effects) {
  std::string text;
  for (std::size_t k = 0; k < effects.size(); ++k) {
    text += (k == 0 ? "" : k + 1 == effects.size() ? " and " : ", ") + std::string(effect_model_name(effects[k]));
  }
  return text;
}

std::vector<std::string> value_names(const std::vector<Effect>& effects) {
  std::vector<std::string> names;
  for (Effect e : effects) {
    for (const std::string& name : effect_value_names(e)) names.push_back(name);
  }
  return names;
}

report::Verdict verdict_of(const Diagnosis& d, const ReportContext& c) {
  report::Verdict v;
  v.title = "Model check of robot " + c.robot_name;
  if (!d.ok || d.steps.empty()) {
    v.tone = report::Tone::kBad;
    v.conclusion = "The check could not run: " + d.message;
    return v;
  }
  const DiagnosisStep& first = d.steps.front();
  const DiagnosisStep& last = d.steps.back();
  const std::vector<Effect> added = added_effects(d);
  if (d.structure_remains) {
    v.tone = report::Tone::kBad;
    v.conclusion = (added.empty() ? "" : effect_list(added) + " explains part of it, but s") +
                   std::string(added.empty() ? "S" : "") + "tructure remains that no known term explains: " +
                   report::strongest_trend_text(residual_trends(last.held_out));
  } else if (!added.empty() || !d.noise.empty()) {
    const std::string what = added.empty()                ? noise_words(d)
                             : d.noise.empty()            ? effect_list(added)
                                                          : effect_list(added) + " with " + noise_words(d);
    v.conclusion = "Explained by " + what + ": with it the model predicts held-out poses down to the noise";
    for (const MimicSet* set : standing_mimic_sets(d)) v.conclusion += ". But " + mimic_text(*set);
  } else {
    v.conclusion = "The " + model_text(first.model) + " model explains the data: no term needed, nothing above the noise";
  }
  v.facts.emplace_back("model fitted", model_text(last.model) + format_text(" (%d samples, %d-fold cross-validation)",
                                                                            d.sample_count, d.folds));
  const CalibrationResult& fit = d.final_fit.ok ? d.final_fit : last.fit;
  const std::string values = report::effect_values_text(fit.calibration.effects, value_names(added));
  v.facts.emplace_back("added", added.empty() ? "nothing" : values.empty() ? effect_list(added) : values);
  if (!d.noise.empty()) v.facts.emplace_back("noisier than stated", noise_words(d));
  // "a -> b" when the workflow changed the model, else the one value.
  const auto change = [&](const char* fmt, double before, double after) {
    return d.steps.size() > 1 ? format_text(fmt, before) + " -> " + format_text(fmt, after) : format_text(fmt, after);
  };
  v.facts.emplace_back(
      "held-out misfit",
      "normalised rms " + change("%.2f", first.held_out.normalized_rms(), last.held_out.normalized_rms()) +
          format_text(" (1 = noise floor; structure p = %.2g); encoder rms ", d.structure_p_value) +
          change("%.1f", 1000.0 * first.held_out.rms_encoder_m, 1000.0 * last.held_out.rms_encoder_m) +
          format_text(" mm (noise %.1f mm), load cell ", 1000.0 * c.noise.encoder_m) +
          change("%.2f", first.held_out.rms_force_n, last.held_out.rms_force_n) +
          format_text(" N (noise %.2f N)", c.noise.force_n));
  std::string anchors = c.nominal ? report::anchors_moved_text(*c.nominal, fit.calibration) : "";
  if (!added.empty() && first.fit.ok) {
    anchors = "the added terms moved them by " + report::anchors_shift_text(first.fit.calibration, fit.calibration) +
              (anchors.empty() ? "" : "; " + anchors);
  }
  if (!anchors.empty()) v.facts.emplace_back("anchors", anchors);
  v.facts.emplace_back("rejected", report::rejected_text(d.gross_errors));
  if (c.truth && fit.ok) {
    double worst = 0.0;
    for (const std::string& name : value_names(added)) {
      worst = std::max(worst, sigma_distance(fit.calibration.effects, c.truth->effects, name));
    }
    v.facts.emplace_back("against truth",
                         "mean anchor error " +
                             change("%.1f", 1000.0 * mean_anchor_error(first.fit.calibration, *c.truth),
                                    1000.0 * mean_anchor_error(fit.calibration, *c.truth)) +
                             " mm" +
                             (added.empty() ? "" : format_text("; added terms %.1f sigma from the true values", worst)));
  }
  return v;
}

std::string sensor_table(const Diagnosis& d) {
  std::vector<report::Evaluation> steps;
  std::vector<std::string> captions;
  for (std::size_t s = 0; s < d.steps.size(); ++s) {
    captions.push_back(format_text("%zu: %s (normalised rms %.3f)", s, model_text(d.steps[s].model).c_str(),
                                   d.steps[s].held_out.normalized_rms()));
  }
  for (std::size_t s = 0; s < d.steps.size(); ++s) steps.push_back({captions[s], &d.steps[s].held_out});
  return report::rms_table(steps);
}

std::string candidates_table(const Diagnosis& d) {
  std::vector<std::vector<std::string>> rows;
  for (std::size_t s = 0; s < d.steps.size(); ++s) {
    for (const CandidateScore& cand : d.steps[s].candidates) {
      const std::string name = candidate_name(cand);
      if (!cand.evaluated) {
        rows.push_back({std::to_string(s), name, "-", "-", "-", "-", "-", cand.failure});
        continue;
      }
      rows.push_back({std::to_string(s), name, cand.noise ? "-" : format_text("%.1f", cand.held_out_drop),
                      cand.noise ? "-" : format_text("%+.1f", cand.t_statistic),
                      format_text("%.1f", cand.fit_chi2_drop), format_text("%.2g", cand.fit_p_value),
                      format_text("%.2g", cand.level), cand.significant ? "significant" : cand.failure});
    }
  }
  return report::table({"step", "candidate", "held-out chi2 drop", "paired t", "fit chi2 drop", "p", "level", "verdict"},
                       rows);
}

}  // namespace

std::string diagnosis_html(const Diagnosis& d, const ReportContext& c) {
  std::string html = report::page_begin("cdpr-calib diagnose: " + c.robot_name) + report::verdict_card(verdict_of(d, c));
  if (d.ok && !d.steps.empty()) {
    const DiagnosisStep& first = d.steps.front();
    const DiagnosisStep& last = d.steps.back();
    const std::string before = "before: " + model_text(first.model), after = "after: " + model_text(last.model);
    std::vector<report::Evaluation> shown{{d.steps.size() > 1 ? before : "held out: " + model_text(first.model),
                                           &first.held_out}};
    if (d.steps.size() > 1) shown.push_back({after, &last.held_out});
    html += "<h2>Held-out residuals per step and sensor</h2>" + sensor_table(d);
    html += "<h2>Residuals of held-out poses" + std::string(d.steps.size() > 1 ? ", before and after" : "") +
            "</h2><p>Model minus measured reading at poses each fit never saw, on shared axes. A slope, a curve or a "
            "drift over the sample order is structure the model lacks.</p>";
    html += report::residual_plots(shown);
    html += "<h2>Normalised residuals</h2>";
    if (c.nominal) html += report::histogram_plots(*c.nominal, shown);
    const CalibrationResult& fit = d.final_fit.ok ? d.final_fit : last.fit;
    if (c.nominal && fit.ok) html += "<h2>Anchors of the final model</h2>" + report::anchor_plots(*c.nominal, fit, c.truth);
    html += report::details("Strongest held-out residual trends, final model",
                            report::trends_table(residual_trends(last.held_out), 10));
    html += report::details("Candidates of every round", candidates_table(d));
    html += report::details(format_text("Rejected readings (%zu)", d.gross_errors.size()),
                            report::rejected_table(d.gross_errors));
  }
  html += report::details("Full text report", "<pre>" + report::html_escape(diagnosis_text(d, c)) + "</pre>");
  return html + report::page_end();
}

std::string mimic_member_name(const MimicMember& m) {
  if (!m.noise) return std::string(effect_model_name(m.effect));
  return std::string(noise_group_description(*m.noise)) + format_text(" x%.2f", m.noise_scale);
}

}  // namespace cdpr::tools
