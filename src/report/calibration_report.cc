#include "src/report/calibration_report.h"

#include <algorithm>
#include <cmath>

#include "src/report/html.h"
#include "src/report/residual_trends.h"
#include "src/report/sections.h"

namespace cdpr::report {
namespace {

std::vector<std::string> fitted_effect_names(const Calibration& cal) {
  std::vector<std::string> names;
  for (const auto& [name, values] : cal.effects) {
    if (!name.ends_with("_sigma")) names.push_back(name);
  }
  return names;
}

Verdict verdict_of(const CalibrationReport& r, const std::vector<Trend>& trends) {
  const CalibrationResult& fit = *r.fit;
  const Calibration& cal = fit.calibration;
  const Robot& robot = *r.nominal;
  Verdict v;
  v.title = r.title;
  const double ratio = fit.degrees_of_freedom > 0 ? fit.chi_square / fit.degrees_of_freedom : 0.0;
  if (fit.misfit) {
    v.tone = Tone::kBad;
    v.conclusion = "The model does not explain the data (chi2/dof " + format("%.2f", ratio) +
                   "): do not trust this calibration as it is; " + misfit_advice(fit.misfit_cause);
    if (!trends.empty()) v.conclusion += ". Strongest residual trend: " + strongest_trend_text(trends);
  } else {
    v.conclusion = "The model explains the data down to the sensor noise";
    if (!fit.gross_errors.empty()) {
      v.tone = Tone::kWarning;
      v.conclusion += format(", with %zu gross sensor error%s left out", fit.gross_errors.size(),
                             fit.gross_errors.size() > 1 ? "s" : "");
    }
  }
  v.facts.emplace_back("model", model_text(cal.model) + format(", fitted to %d samples", cal.samples));
  const std::string terms = effect_values_text(cal.effects, fitted_effect_names(cal));
  v.facts.emplace_back("fitted terms", terms.empty() ? "none beyond anchors and encoder offsets" : terms);
  v.facts.emplace_back("misfit", format("chi2/dof %.2f (1 at the noise floor, p = %.2g); rms encoder %.1f mm (noise "
                                        "%.1f mm), load cell %.2f N (noise %.2f N)",
                                        ratio, fit.misfit_probability, 1000.0 * cal.fit.rms_encoder_m,
                                        1000.0 * robot.noise.encoder_m, cal.fit.rms_force_n, robot.noise.force_n));
  v.facts.emplace_back("anchors", anchors_moved_text(robot, cal));
  v.facts.emplace_back("rejected", rejected_text(fit.gross_errors));
  if (r.truth) {
    double sum = 0.0;
    for (std::size_t i = 0; i < cal.winches.size() && i < r.truth->winches.size(); ++i) {
      sum += (cal.winches[i].anchor_world - r.truth->winches[i].anchor_world).norm();
    }
    v.facts.emplace_back("against truth",
                         format("mean anchor error %.2f mm", 1000.0 * sum / std::max<std::size_t>(1, cal.winches.size())));
  }
  for (const auto& fact : r.run_facts) v.facts.push_back(fact);
  return v;
}

std::string winch_table(const Robot& nominal, const Calibration& cal) {
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < cal.winches.size(); ++i) {
    const WinchCalibration& w = cal.winches[i];
    const double moved = i < nominal.winches.size() ? (w.anchor_world - nominal.winches[i].anchor_world).norm() : 0.0;
    rows.push_back({std::to_string(i), format("%.4f, %.4f, %.4f", w.anchor_world.x(), w.anchor_world.y(), w.anchor_world.z()),
                    format("%.2f, %.2f, %.2f", 1000 * w.anchor_sigma.x(), 1000 * w.anchor_sigma.y(), 1000 * w.anchor_sigma.z()),
                    format("%.4f", moved), format("%.4f +- %.2f", w.offset_m, 1000 * w.offset_sigma_m)});
  }
  return table({"cable", "anchor x, y, z [m]", "1-sigma [mm]", "moved from nominal [m]", "offset [m] +- [mm]"}, rows);
}

std::string fit_table(const CalibrationResult& fit) {
  const SolverSummary& s = fit.solver;
  return table({"quantity", "value"},
               {{"solver", fit.message},
                {"cost start -> end", format("%.6g -> %.6g", s.initial_cost, s.final_cost)},
                {"iterations (accepted)", format("%d (%d)", s.iterations, s.successful_steps)},
                {"chi2 / dof", format("%.1f / %d", fit.chi_square, fit.degrees_of_freedom)},
                {"p of the model-fit test", format("%.3g", fit.misfit_probability)},
                {"model warning", fit.calibration.model_warning.empty() ? "none" : fit.calibration.model_warning}});
}

}  // namespace

HeldOutEvaluation fitted_residuals(const Robot& robot, const std::vector<Sample>& samples,
                                   const CalibrationOptions& options, const CalibrationResult& fit) {
  if (options.cable_model != CableModelKind::kCatenary) {
    HeldOutEvaluation none;
    none.message = "residual plots need the catenary model";
    return none;
  }
  CalibrationOptions quiet = options;
  quiet.progress = nullptr;
  return evaluate_held_out(robot, samples, quiet, fit);
}

std::string calibration_report_html(const CalibrationReport& r) {
  const bool residuals = r.residuals && r.residuals->ok && !r.residuals->poses.empty();
  const std::vector<Trend> trends = residuals ? residual_trends(*r.residuals) : std::vector<Trend>{};
  std::string html = page_begin(r.title) + verdict_card(verdict_of(r, trends));
  html += "<h2>Anchors</h2>" + anchor_plots(*r.nominal, *r.fit, r.truth);
  if (residuals) {
    const std::vector<Evaluation> fitted{{"residuals of the fit (each pose re-solved with the calibration held)",
                                          r.residuals}};
    html += "<h2>Residuals of the fit</h2><p>Model minus measured reading at each sample. Structure here (a slope, a "
            "curve, a step in sample order) is what the model does not explain; "
            "<code>cdpr-calib diagnose</code> names the term that would.</p>";
    html += residual_plots(fitted);
    html += "<h2>Normalised residuals</h2>" + histogram_plots(*r.nominal, fitted);
    html += details("Residual trends (strongest first)", trends_table(trends, 10));
    html += details("Residual rms per sensor", rms_table(fitted));
  } else if (r.residuals) {
    html += "<p>No residual plots: " + html_escape(r.residuals->message) + "</p>";
  }
  html += details("Anchors and offsets", winch_table(*r.nominal, r.fit->calibration));
  html += details(format("Rejected readings (%zu)", r.fit->gross_errors.size()), rejected_table(r.fit->gross_errors));
  html += details("Fit statistics", fit_table(*r.fit));
  return html + page_end();
}

std::string fitted_calibration_report_html(const Robot& robot, const std::vector<Sample>& samples,
                                           const CalibrationOptions& options, const CalibrationResult& fit,
                                           const std::optional<Truth>& truth,
                                           std::vector<std::pair<std::string, std::string>> facts) {
  const HeldOutEvaluation residuals = fitted_residuals(robot, samples, options, fit);
  const CalibrationReport report{"Calibration of robot " + robot.name, &robot, &fit, &residuals, truth,
                                 std::move(facts)};
  return calibration_report_html(report);
}

}  // namespace cdpr::report
