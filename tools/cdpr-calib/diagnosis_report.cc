#include "diagnosis_report.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "residual_trends.h"
#include "svg_plot.h"

namespace cdpr::tools {
namespace {

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

// One machine-readable line for scripts (tools/diagnose-acceptance.sh).
void append_summary(std::string& out, const Diagnosis& d, const ReportContext& c) {
  // The terms of the final model beyond the starting one (a term replaced on the way is not named).
  const std::vector<Effect> named = added_effects(d);
  std::string added;
  for (Effect e : named) added += (added.empty() ? "" : ",") + std::string(effect_model_name(e));
  append(out, "summary: added=%s structure=%s structure_p=%.2g normalized_rms_start=%.4f normalized_rms_final=%.4f",
         added.empty() ? "none" : added.c_str(), d.structure_remains ? "remains" : "none", d.structure_p_value,
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
    if (s > 0 && step.removed) {
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
      const std::string name(effect_model_name(cand.effect));
      if (!cand.evaluated) {
        append(out, "    %-14s not evaluated: %s\n", name.c_str(), cand.failure.c_str());
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
      append(out, " %s%s%s", d.steps[s].removed ? "removed:" : "", std::string(effect_model_name(d.steps[s].added)).c_str(),
             d.steps[s].replaced ? (" (in place of " + std::string(effect_model_name(*d.steps[s].replaced)) + ")").c_str()
                                 : "");
    }
    append(out, "; held-out normalized rms %.3f -> %.3f, encoder rms %.4f -> %.4f m, force rms %.2f -> %.2f N\n",
           first.held_out.normalized_rms(), last.held_out.normalized_rms(), first.held_out.rms_encoder_m,
           last.held_out.rms_encoder_m, first.held_out.rms_force_n, last.held_out.rms_force_n);
  }
  if (d.structure_remains) {
    append(out, "STRUCTURE REMAINS that no known effect explains: held-out normalized rms %.3f, p = %.2g against the "
                "noise; see the trends above\n", last.held_out.normalized_rms(), d.structure_p_value);
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

// The residual plots of one step's held-out poses, grouped by residual channel.
std::string step_plots(const HeldOutEvaluation& h, const std::string& heading) {
  const std::vector<ResidualSeries> all = residual_series(h);
  std::string html = "<h3>" + html_escape(heading) + "</h3><div class=\"plots\">";
  const auto plot = [&](const std::string& prefix, const std::string& against, const std::string& title,
                        const std::string& y_label) {
    std::vector<PlotSeries> series;
    for (const ResidualSeries& s : all) {
      if (s.sensor.rfind(prefix, 0) == 0 && s.against == against) series.push_back({s.sensor, s.x, s.residual});
    }
    html += svg_scatter({title, against, y_label}, series);
  };
  plot("encoder", "cable length [m]", "encoder residual vs cable length", "residual [m]");
  plot("encoder", "cable tension [N]", "encoder residual vs tension", "residual [m]");
  plot("encoder", "platform height [m]", "encoder residual vs height", "residual [m]");
  plot("height", "platform height [m]", "attachment-height residual (Eq. 15)", "residual [m]");
  plot("load cell", "reference tension [N]", "load-cell residual vs tension", "residual [N]");
  plot("load cell", "platform height [m]", "load-cell residual vs height", "residual [N]");
  return html + "</div>";
}

std::string sensor_table(const Diagnosis& d) {
  std::string html = "<table><tr><th>step</th><th>model</th><th>normalized rms</th>";
  for (int i = 0; i < kCableCount; ++i) html += "<th>encoder " + std::to_string(i) + " rms [m]</th>";
  html += "<th>load cell rms [N]</th></tr>";
  for (std::size_t s = 0; s < d.steps.size(); ++s) {
    const HeldOutEvaluation& h = d.steps[s].held_out;
    std::string row;
    append(row, "<tr><td>%zu</td><td>%s</td><td>%.3f</td>", s, html_escape(model_text(d.steps[s].model)).c_str(),
           h.normalized_rms());
    for (int i = 0; i < kCableCount; ++i) {
      double sum = 0.0;
      for (const HeldOutPose& p : h.poses) sum += std::pow(p.prediction.encoder_residual_m[i], 2);
      append(row, "<td>%.4f</td>", std::sqrt(sum / std::max<std::size_t>(1, h.poses.size())));
    }
    append(row, "<td>%.2f</td></tr>", h.rms_force_n);
    html += row;
  }
  return html + "</table>";
}

}  // namespace

std::string diagnosis_html(const Diagnosis& d, const ReportContext& c) {
  std::string html =
      "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>cdpr-calib diagnose: " + html_escape(c.robot_name) +
      "</title><style>body{font-family:sans-serif;margin:1em 2em}pre{background:#f6f6f6;padding:.8em}"
      ".plots{display:flex;flex-wrap:wrap;gap:8px}table{border-collapse:collapse}td,th{border:1px solid #ccc;"
      "padding:2px 6px;text-align:right}</style></head><body>";
  html += "<h1>Model discrepancy: " + html_escape(c.robot_name) + "</h1>";
  html += "<pre>" + html_escape(diagnosis_text(d, c)) + "</pre>";
  if (!d.ok || d.steps.empty()) return html + "</body></html>";
  html += "<h2>Held-out residuals per step and sensor</h2>" + sensor_table(d);
  html += "<h2>Residual structure on held-out poses</h2>";
  html += step_plots(d.steps.front().held_out, "before: " + model_text(d.steps.front().model));
  if (d.steps.size() > 1) html += step_plots(d.steps.back().held_out, "after: " + model_text(d.steps.back().model));
  return html + "</body></html>";
}

}  // namespace cdpr::tools
