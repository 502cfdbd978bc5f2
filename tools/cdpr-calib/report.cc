#include "report.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include "src/report/sections.h"
#include "src/report/suspect_group_note.h"

namespace cdpr::tools {

void print_iteration(std::FILE* out, const IterationSummary& it) {
  std::fprintf(out, "iter %3d  cost %.6e  change %+.3e  |grad| %.3e  |step| %.3e  radius %.2e  %s\n", it.iteration,
               it.cost, -it.cost_change, it.gradient_max_norm, it.step_norm, it.trust_radius,
               it.step_accepted ? "accepted" : "rejected");
}

void print_stages(std::FILE* out, const std::vector<CalibrationStage>& stages) {
  std::fprintf(out, "stages (docs/calibration.md, \"The stages of a calibration\"):\n");
  for (const CalibrationStage& s : stages) {
    const std::string name = std::string(2 * static_cast<std::size_t>(s.depth), ' ') + s.name +
                             (s.fallback ? " [fallback]" : "");
    char cost[32] = "";
    if (std::isfinite(s.cost)) std::snprintf(cost, sizeof cost, "cost %.6e", s.cost);
    std::fprintf(out, "  %-58s %5d it  %-17s  %s\n", name.c_str(), s.iterations, cost, s.outcome.c_str());
  }
}

void print_summary(std::FILE* out, const CalibrationResult& result, const Robot& robot) {
  const SolverSummary& s = result.solver;
  std::fprintf(out, "\nsolver: %s\n", result.message.c_str());
  std::fprintf(out, "cost: %.6e -> %.6e in %d iterations (%d accepted steps)\n", s.initial_cost, s.final_cost,
               s.iterations, s.successful_steps);
  if (!result.rejected_samples.empty()) {
    std::fprintf(out, "rejected samples (the model cannot be started from them):");
    for (int id : result.rejected_samples) std::fprintf(out, " %d", id);
    std::fprintf(out, "\n");
  }
  print_gross_errors(out, result.gross_errors);
  if (!result.ok) return;
  const Calibration& cal = result.calibration;
  std::string model;
  for (const std::string& term : cal.model) model += (model.empty() ? "" : ",") + term;
  std::fprintf(out, "samples used: %d   model: %s\n", cal.samples, model.empty() ? "?" : model.c_str());
  std::fprintf(out, "rms encoder residual: %.4f m (noise %.4f m)   rms force residual: %.3f N (noise %.3f N)\n",
               cal.fit.rms_encoder_m, robot.noise.encoder_m, cal.fit.rms_force_n, robot.noise.force_n);
  std::fprintf(out, "%-6s %32s %28s %18s\n", "cable", "anchor [m]", "anchor sigma [m]", "offset +- sigma [m]");
  for (std::size_t i = 0; i < cal.winches.size(); ++i) {
    const WinchCalibration& w = cal.winches[i];
    std::fprintf(out, "%-6zu %10.4f %10.4f %10.4f   %8.4f %8.4f %8.4f   %9.4f +- %.4f\n", i, w.anchor_world.x(),
                 w.anchor_world.y(), w.anchor_world.z(), w.anchor_sigma.x(), w.anchor_sigma.y(), w.anchor_sigma.z(),
                 w.offset_m, w.offset_sigma_m);
  }
  print_effects(out, cal.effects);
  print_term_tests(out, result);
  print_noise_scales(out, result.noise);
  if (!cal.model_warning.empty()) std::fprintf(out, "MODEL WARNING: %s\n", cal.model_warning.c_str());
}

void print_term_tests(std::FILE* out, const CalibrationResult& result) {
  if (result.term_tests.empty()) return;
  std::fprintf(out, "terms not in the model (score test at the fit; level %.1e each):", result.term_test_level);
  bool asked = false;
  for (const TermTest& t : result.term_tests) {
    std::fprintf(out, " %s", std::string(effect_model_name(t.effect)).c_str());
    if (!t.identifiable) {
      std::fprintf(out, " not identifiable;");
      continue;
    }
    std::fprintf(out, " %.1f/%d p %.1e%s;", t.statistic, t.dof, t.p, t.asked_for ? " ASKED FOR" : "");
    asked = asked || t.asked_for;
  }
  std::fprintf(out, " %s\n", asked ? "the model lacks a term" : "none asked for");
}

void print_noise_scales(std::FILE* out, const std::vector<NoiseComponent>& noise) {
  if (noise.empty()) return;
  // The level of the score tests' family: noise that the data call larger
  // than stated by this much is worth a word, not a refusal.
  constexpr double kNoisierLevel = 1e-6;
  std::fprintf(out, "noise the residuals imply (x robot.toml's sigma; variance components):");
  std::string noisier;
  for (const NoiseComponent& c : noise) {
    std::fprintf(out, " %s %.2f%s", std::string(noise_group_name(c.group)).c_str(), c.scale,
                 &c == &noise.back() ? "" : ",");
    if (c.p_high < kNoisierLevel) noisier += (noisier.empty() ? "" : ", ") + std::string(noise_group_name(c.group));
  }
  std::fprintf(out, "%s\n", noisier.empty() ? "" : ("; NOISIER THAN STATED: " + noisier).c_str());
}

void print_gross_errors(std::FILE* out, const std::vector<SensorReading>& rejected) {
  if (rejected.empty()) return;
  std::fprintf(out, "gross errors (normalised residual at the robust fit; left out of the final fit):\n");
  for (const SensorReading& r : rejected) {
    std::fprintf(out, "  row %4d  %-7s", r.row, sensor_name(r.sensor));
    if (r.sensor == SensorKind::kEncoder) std::fprintf(out, " cable %d", r.cable);
    else std::fprintf(out, "        ");
    std::fprintf(out, "  %+8.1f sigma", r.value);
    if (r.group != 0) std::fprintf(out, "  suspect group: %s", report::suspect_group_text(rejected, r).c_str());
    std::fprintf(out, "\n");
  }
  if (std::any_of(rejected.begin(), rejected.end(), [](const SensorReading& r) { return r.group != 0; })) {
    std::fprintf(out, "  %s\n", report::kSuspectGroupNote);
  }
}

void print_effects(std::FILE* out, const EffectValues& effects) {
  for (const auto& [name, values] : effects) {
    if (name.ends_with("_sigma")) continue;
    const auto sigma = effects.find(name + "_sigma");
    std::fprintf(out, "effect %-16s", name.c_str());
    for (std::size_t j = 0; j < values.size(); ++j) {
      std::fprintf(out, " %.6g", values[j]);
      if (sigma != effects.end() && j < sigma->second.size()) std::fprintf(out, " +- %.2g", sigma->second[j]);
    }
    std::fprintf(out, "\n");
  }
}

void print_truth_comparison(std::FILE* out, const Calibration& calibration, const Truth& truth) {
  std::fprintf(out, "\nagainst truth:\n%-6s %14s %14s %14s\n", "cable", "anchor err [m]", "offset err [m]",
               "err/sigma max");
  double anchor_sum = 0.0, offset_sum = 0.0;
  const std::size_t n = std::min(calibration.winches.size(), truth.winches.size());
  for (std::size_t i = 0; i < n; ++i) {
    const WinchCalibration& w = calibration.winches[i];
    const Eigen::Vector3d err = w.anchor_world - truth.winches[i].anchor_world;
    const double offset_err = w.offset_m - truth.winches[i].offset_m;
    const double normalised = std::max(err.cwiseQuotient(w.anchor_sigma).cwiseAbs().maxCoeff(),
                                       std::abs(offset_err) / w.offset_sigma_m);
    std::fprintf(out, "%-6zu %14.4f %14.4f %14.2f\n", i, err.norm(), offset_err, normalised);
    anchor_sum += err.norm();
    offset_sum += std::abs(offset_err);
  }
  if (n > 0) std::fprintf(out, "mean   %14.4f %14.4f\n", anchor_sum / n, offset_sum / n);
  if (!truth.effects.empty()) {
    std::fprintf(out, "true effects:\n");
    print_effects(out, truth.effects);
  }
  for (const std::string& name : truth.uncompared_effects) {
    std::fprintf(out, "true effect %s: not compared (not a number or a list of numbers)\n", name.c_str());
  }
  print_outlier_recall(out, calibration.rejected, truth.outliers);
}

void print_outlier_recall(std::FILE* out, const std::vector<SensorReading>& rejected,
                          const std::vector<SensorReading>& planted) {
  if (planted.empty() && rejected.empty()) return;
  int found = 0;
  for (const SensorReading& p : planted) {
    const auto named = std::find_if(rejected.begin(), rejected.end(), [&](const SensorReading& r) {
      return r.row == p.row && r.sensor == p.sensor && (r.sensor == SensorKind::kForce || r.cable == p.cable);
    });
    const bool hit = named != rejected.end();
    found += hit;
    const std::string group =
        named != rejected.end() && named->group != 0 ? " (suspect group: " + report::suspect_group_text(rejected, *named) + ")" : "";
    std::fprintf(out, "planted %-7s row %4d cable %d error %+.3g: %s%s\n", sensor_name(p.sensor), p.row, p.cable,
                 p.value, hit ? "rejected" : "NOT rejected", group.c_str());
  }
  std::fprintf(out, "planted gross errors rejected: %d of %zu; rejected readings: %zu\n", found, planted.size(),
               rejected.size());
}

std::string utc_timestamp_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace cdpr::tools
