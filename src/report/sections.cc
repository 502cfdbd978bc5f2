#include "src/report/sections.h"

#include <algorithm>
#include <cmath>

#include "src/report/html.h"
#include "src/report/residual_trends.h"
#include "src/report/svg_plot.h"

namespace cdpr::report {
namespace {

// The x-y covariance [m^2] of anchor i: from the fit's covariance when it
// has one (AnchorKey(i) first in global_keys order), else the per-axis sigmas.
Eigen::Matrix2d anchor_covariance(const CalibrationResult& fit, int i) {
  // calibrate() orders the globals AnchorKey(i) (3), OffsetKey(i) (1) per cable, then the effects.
  const std::size_t key = 2 * static_cast<std::size_t>(i);
  const Eigen::Index row = 4 * i;
  if (key < fit.global_keys.size() && fit.global_keys[key] == AnchorKey(i) && fit.global_covariance.rows() >= row + 2) {
    return fit.global_covariance.block<2, 2>(row, row);
  }
  const Eigen::Vector3d s = fit.calibration.winches.at(static_cast<std::size_t>(i)).anchor_sigma;
  return Eigen::Vector2d(s.x() * s.x(), s.y() * s.y()).asDiagonal();
}

struct Channel {
  std::string prefix, against, title, y_label;
  double scale;  // residual unit -> plotted unit
};

const std::vector<Channel>& channels() {
  static const std::vector<Channel> list = {
      {"encoder", kSampleOrder, "encoder residual vs sample order (time)", "residual [mm]", 1000.0},
      {"encoder", "cable length [m]", "encoder residual vs cable length", "residual [mm]", 1000.0},
      {"encoder", "cable tension [N]", "encoder residual vs tension", "residual [mm]", 1000.0},
      {"encoder", "platform height [m]", "encoder residual vs height", "residual [mm]", 1000.0},
      {"height", "platform height [m]", "attachment-height residual (Eq. 15)", "residual [mm]", 1000.0},
      {"load cell", "reference tension [N]", "load-cell residual vs tension", "residual [N]", 1.0},
      {"load cell", kSampleOrder, "load-cell residual vs sample order (time)", "residual [N]", 1.0},
  };
  return list;
}

std::vector<PlotSeries> channel_series(const std::vector<ResidualSeries>& all, const Channel& c) {
  std::vector<PlotSeries> out;
  for (const ResidualSeries& s : all) {
    if (s.sensor.rfind(c.prefix, 0) != 0 || s.against != c.against) continue;
    PlotSeries p{s.cable >= 0 ? "cable " + std::to_string(s.cable) : s.sensor, s.x, s.residual,
                 s.cable >= 0 ? s.cable : kLoadCellColour};
    for (double& y : p.y) y *= c.scale;
    out.push_back(std::move(p));
  }
  return out;
}

std::string figure(const std::string& svg, const std::string& caption) {
  return "<figure>" + svg + "<figcaption>" + html_escape(caption) + "</figcaption></figure>";
}

// A length in the unit that reads best: "12.3 mm", "1.07 m".
std::string length_text(double m) { return std::abs(m) < 1.0 ? format("%.3g mm", 1000.0 * m) : format("%.3g m", m); }

}  // namespace

std::string model_text(const std::vector<std::string>& model) {
  std::string text;
  for (const std::string& term : model) text += (text.empty() ? "" : " + ") + term;
  return text.empty() ? "?" : text;
}

std::string effect_unit(const std::string& name) {
  if (const auto unit = effect_value_unit(name)) return std::string(*unit);
  // The simulator's truth.toml also names effects no model term describes.
  if (name == "wind_force") return "N";
  if (name == "encoder_drift") return "m";
  return "";
}

std::string effect_values_text(const EffectValues& effects, const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    const auto value = effects.find(name);
    if (value == effects.end()) continue;
    const auto sigma = effects.find(name + "_sigma");
    std::string values;
    for (std::size_t j = 0; j < value->second.size(); ++j) {
      values += format("%s%.4g", j ? ", " : "", value->second[j]);
      if (sigma != effects.end() && j < sigma->second.size()) values += format(" +- %.2g", sigma->second[j]);
    }
    const std::string unit = effect_unit(name);
    text += (text.empty() ? "" : "; ") + name + " = " + (value->second.size() > 1 ? "(" + values + ")" : values) +
            (unit.empty() ? "" : " " + unit);
  }
  return text;
}

std::string anchors_moved_text(const Robot& nominal, const Calibration& calibration) {
  double sum = 0.0, largest = -1.0, sigma = 0.0;
  int which = 0;
  const std::size_t n = std::min(calibration.winches.size(), nominal.winches.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double d = (calibration.winches[i].anchor_world - nominal.winches[i].anchor_world).norm();
    sum += d;
    if (d > largest) largest = d, which = static_cast<int>(i);
    sigma = std::max(sigma, calibration.winches[i].anchor_sigma.maxCoeff());
  }
  if (n == 0) return "no anchors";
  return "from nominal: mean " + length_text(sum / static_cast<double>(n)) + ", largest " + length_text(largest) +
         format(" (anchor %d); largest 1-sigma ", which) + length_text(sigma);
}

std::string anchors_shift_text(const Calibration& from, const Calibration& to) {
  double largest = -1.0, in_sigma = 0.0;
  int which = 0;
  for (std::size_t i = 0; i < std::min(from.winches.size(), to.winches.size()); ++i) {
    const Eigen::Vector3d d = to.winches[i].anchor_world - from.winches[i].anchor_world;
    if (d.norm() > largest) {
      largest = d.norm();
      which = static_cast<int>(i);
      in_sigma = d.cwiseQuotient(to.winches[i].anchor_sigma.cwiseMax(1e-12)).cwiseAbs().maxCoeff();
    }
  }
  if (largest < 0.0) return "?";
  return "largest " + length_text(largest) + format(" (anchor %d, %.1f sigma)", which, in_sigma);
}

std::string suspect_group_text(const std::vector<SensorReading>& rejected, const SensorReading& reading) {
  if (reading.group == 0) return {};
  std::string text;
  for (const SensorReading& r : rejected) {
    if (r.row != reading.row || r.group != reading.group) continue;
    text += (text.empty() ? "" : " or ") + std::string(sensor_name(r.sensor)) +
            (r.sensor == SensorKind::kEncoder ? format(" cable %d", r.cable) : "");
  }
  return text;
}

std::string rejected_text(const std::vector<SensorReading>& rejected, int shown) {
  if (rejected.empty()) return "none";
  std::string text = format("%zu: ", rejected.size());
  for (std::size_t k = 0; k < rejected.size() && static_cast<int>(k) < shown; ++k) {
    const SensorReading& r = rejected[k];
    text += format("%srow %d %s%s %+.1f sigma", k ? "; " : "", r.row, sensor_name(r.sensor),
                   r.sensor == SensorKind::kEncoder ? format(" cable %d", r.cable).c_str() : "", r.value);
    if (r.group != 0) text += " (suspect group: " + suspect_group_text(rejected, r) + ")";
  }
  if (static_cast<int>(rejected.size()) > shown) text += format("; and %zu more", rejected.size() - shown);
  return text;
}

std::string rejected_table(const std::vector<SensorReading>& rejected) {
  const bool groups =
      std::any_of(rejected.begin(), rejected.end(), [](const SensorReading& r) { return r.group != 0; });
  std::vector<std::vector<std::string>> rows;
  for (const SensorReading& r : rejected) {
    rows.push_back({std::to_string(r.row), sensor_name(r.sensor),
                    r.sensor == SensorKind::kEncoder ? std::to_string(r.cable) : "-", format("%+.1f", r.value)});
    if (groups) rows.back().push_back(r.group != 0 ? suspect_group_text(rejected, r) : "-");
  }
  std::vector<std::string> header{"row (samples.csv id)", "sensor", "cable", "residual [sigma]"};
  if (groups) header.push_back("suspect group (one of them is wrong)");
  return table(header, rows);
}

std::string residual_plots(const std::vector<Evaluation>& evaluations) {
  std::vector<std::vector<ResidualSeries>> all;
  for (const Evaluation& e : evaluations) all.push_back(residual_series(*e.held_out));
  std::string html;
  for (const Channel& c : channels()) {
    std::vector<std::vector<PlotSeries>> plots;
    for (const auto& series : all) plots.push_back(channel_series(series, c));
    std::vector<const std::vector<PlotSeries>*> pointers;
    for (const auto& p : plots) pointers.push_back(&p);
    PlotSpec spec{c.title, c.against, c.y_label, shared_ticks(pointers, true), shared_ticks(pointers, false)};
    html += "<div class=\"plots\">";
    for (std::size_t k = 0; k < plots.size(); ++k) {
      html += figure(svg_scatter(spec, plots[k]), evaluations[k].caption);
    }
    html += "</div>\n";
  }
  return html;
}

std::string histogram_plots(const Robot& robot, const std::vector<Evaluation>& evaluations) {
  std::vector<NormalisedResiduals> residuals;
  double peak = 0.0;
  for (const Evaluation& e : evaluations) {
    residuals.push_back(normalised_residuals(robot, *e.held_out));
    peak = std::max({peak, normal_histogram_peak(residuals.back().encoder), normal_histogram_peak(residuals.back().force)});
  }
  PlotSpec spec{"", "normalised residual [sigma]", "density [1/sigma]", std::nullopt, nice_ticks(0.0, peak, 4)};
  std::string html = "<div class=\"plots\">";
  for (std::size_t k = 0; k < residuals.size(); ++k) {
    spec.title = "encoders, all cables";
    html += figure(svg_normal_histogram(spec, residuals[k].encoder, 0), evaluations[k].caption);
    spec.title = "load cell";
    html += figure(svg_normal_histogram(spec, residuals[k].force, kLoadCellColour), evaluations[k].caption);
  }
  return html + "</div>\n";
}

std::string anchor_plots(const Robot& nominal, const CalibrationResult& fit, const std::optional<Truth>& truth) {
  std::vector<AnchorTopView> views;
  const Calibration& cal = fit.calibration;
  for (std::size_t i = 0; i < cal.winches.size() && i < nominal.winches.size(); ++i) {
    AnchorTopView v;
    v.name = "anchor " + std::to_string(i);
    v.colour = static_cast<int>(i);
    v.fitted = cal.winches[i].anchor_world.head<2>();
    v.nominal = nominal.winches[i].anchor_world.head<2>();
    if (truth && i < truth->winches.size()) v.truth = truth->winches[i].anchor_world.head<2>();
    v.covariance = anchor_covariance(fit, static_cast<int>(i));
    views.push_back(v);
  }
  double half_width = 0.0;
  for (const AnchorTopView& v : views) half_width = std::max(half_width, anchor_view_half_width(v));
  std::string html = "<div class=\"plots\">" + figure(svg_anchor_layout(views),
                                                     "filled dot: where the fit puts the anchor; open circle: its "
                                                     "nominal position in robot.toml");
  for (const AnchorTopView& v : views) {
    html += figure(svg_anchor_top_view(v, half_width),
                   "centred on the fitted anchor (filled dot); solid: 1 sigma, dashed: 3 sigma; open circle: nominal "
                   "(an arrow to the edge when off the panel); all panels at one scale");
  }
  return html + "</div>\n";
}

std::string rms_table(const std::vector<Evaluation>& evaluations) {
  std::vector<std::string> header{"residuals"};
  for (int i = 0; i < kCableCount; ++i) header.push_back(format("encoder %d rms [mm]", i));
  header.push_back("load cell rms [N]");
  std::vector<std::vector<std::string>> rows;
  for (const Evaluation& e : evaluations) {
    std::vector<std::string> row{e.caption};
    for (int i = 0; i < kCableCount; ++i) {
      row.push_back(format("%.2f", 1000.0 * encoder_rms_m(e.held_out->poses, i)));
    }
    row.push_back(format("%.2f", e.held_out->rms_force_n));
    rows.push_back(row);
  }
  return table(header, rows);
}

}  // namespace cdpr::report

namespace cdpr::report {

std::string trends_table(const std::vector<Trend>& trends, int count) {
  std::vector<std::vector<std::string>> rows;
  for (int k = 0; k < count && k < static_cast<int>(trends.size()); ++k) {
    const Trend& t = trends[static_cast<std::size_t>(k)];
    const double change = t.slope * t.x_span * (t.unit == "m" ? 1000.0 : 1.0);
    rows.push_back({t.sensor, t.against, format("%+.3g %s", change, t.unit == "m" ? "mm" : t.unit.c_str()),
                    format("%+.2f", t.correlation), format("%+.1f", t.t_statistic), format("%.1g", t.p_value)});
  }
  return table({"residual", "against", "change over the data", "r", "t", "p"}, rows);
}

}  // namespace cdpr::report
