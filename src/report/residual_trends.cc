#include "src/report/residual_trends.h"

#include <algorithm>
#include <cmath>

#include "solver/calibration/chi_square.h"
#include "src/report/html.h"

namespace cdpr::report {
namespace {

// Two-sided p of Student's t with nu degrees of freedom through the normal
// z of the same tail (Wallace's approximation; good to a few per cent of
// the p down to 1e-10 for nu >= 5, and only the ranking and its order of
// magnitude are reported).
double t_two_sided_p(double t, double nu) {
  if (nu < 1.0) return 1.0;
  const double z = std::sqrt(nu * std::log1p(t * t / nu)) * (1.0 - 1.0 / (8.0 * nu)) /
                   std::sqrt(1.0 + 1.0 / (4.0 * nu));
  return std::min(1.0, 2.0 * normal_upper_tail(std::abs(z)));
}

// The change of a trend over its data, in the residual's reading unit.
std::string change_text(const Trend& t) {
  const double change = t.slope * t.x_span;
  const std::string over = t.against == kSampleOrder ? "over the run" : "over its range of " + t.against;
  if (t.unit == "m") return format("%+.3g mm %s", 1000.0 * change, over.c_str());
  return format("%+.3g %s %s", change, t.unit.c_str(), over.c_str());
}

std::string plain(const std::string& against) { return against.substr(0, against.find(" [")); }

}  // namespace

std::vector<ResidualSeries> residual_series(const HeldOutEvaluation& held_out) {
  std::vector<ResidualSeries> series;
  for (int i = 0; i < kCableCount; ++i) {
    const std::string encoder = "encoder " + std::to_string(i);
    ResidualSeries by_length{encoder, "cable length [m]", "m", i, {}, {}};
    ResidualSeries by_tension{encoder, "cable tension [N]", "m", i, {}, {}};
    ResidualSeries by_height{encoder, "platform height [m]", "m", i, {}, {}};
    ResidualSeries by_order{encoder, kSampleOrder, "m", i, {}, {}};
    ResidualSeries height{"height " + std::to_string(i), "platform height [m]", "m", i, {}, {}};
    for (const HeldOutPose& pose : held_out.poses) {
      const double z = pose.world_T_platform.position_world.z();
      height.x.push_back(z);
      height.residual.push_back(pose.prediction.height_residual_m[i]);
      // A reading left out as a gross error is no trend of the model's.
      if (pose.sample.encoder_left_out[i]) continue;
      const double r = pose.prediction.encoder_residual_m[i];
      by_length.x.push_back(pose.prediction.payout_m[i]);
      by_length.residual.push_back(r);
      by_tension.x.push_back(pose.prediction.tension_n[i]);
      by_tension.residual.push_back(r);
      by_height.x.push_back(z);
      by_height.residual.push_back(r);
      by_order.x.push_back(pose.sample.id);
      by_order.residual.push_back(r);
    }
    for (ResidualSeries* s : {&by_length, &by_tension, &by_height, &height, &by_order}) series.push_back(std::move(*s));
  }
  ResidualSeries force{"load cell", "reference tension [N]", "N", -1, {}, {}};
  ResidualSeries force_height{"load cell", "platform height [m]", "N", -1, {}, {}};
  ResidualSeries force_order{"load cell", kSampleOrder, "N", -1, {}, {}};
  for (const HeldOutPose& pose : held_out.poses) {
    if (pose.sample.force_left_out) continue;
    force.x.push_back(pose.sample.force_n);
    force.residual.push_back(pose.prediction.force_residual_n);
    force_height.x.push_back(pose.world_T_platform.position_world.z());
    force_height.residual.push_back(pose.prediction.force_residual_n);
    force_order.x.push_back(pose.sample.id);
    force_order.residual.push_back(pose.prediction.force_residual_n);
  }
  series.push_back(std::move(force));
  series.push_back(std::move(force_height));
  series.push_back(std::move(force_order));
  return series;
}

std::vector<Trend> residual_trends(const HeldOutEvaluation& held_out) {
  std::vector<Trend> trends;
  for (const ResidualSeries& s : residual_series(held_out)) {
    const double n = static_cast<double>(s.x.size());
    if (n < 4) continue;
    double mx = 0.0, my = 0.0;
    for (std::size_t j = 0; j < s.x.size(); ++j) {
      mx += s.x[j] / n;
      my += s.residual[j] / n;
    }
    double sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (std::size_t j = 0; j < s.x.size(); ++j) {
      sxx += (s.x[j] - mx) * (s.x[j] - mx);
      syy += (s.residual[j] - my) * (s.residual[j] - my);
      sxy += (s.x[j] - mx) * (s.residual[j] - my);
    }
    if (!(sxx > 0.0) || !(syy > 0.0)) continue;
    Trend t{s.sensor, s.against, s.unit, s.cable, sxy / sxx, sxy / std::sqrt(sxx * syy), 0.0, 1.0, 0.0,
            static_cast<int>(n)};
    t.t_statistic = t.correlation * std::sqrt((n - 2.0) / std::max(1e-12, 1.0 - t.correlation * t.correlation));
    t.p_value = t_two_sided_p(t.t_statistic, n - 2.0);
    const auto [lo, hi] = std::minmax_element(s.x.begin(), s.x.end());
    t.x_span = *hi - *lo;
    trends.push_back(t);
  }
  std::stable_sort(trends.begin(), trends.end(),
                   [](const Trend& a, const Trend& b) { return std::abs(a.t_statistic) > std::abs(b.t_statistic); });
  return trends;
}

std::string strongest_trend_text(const std::vector<Trend>& trends, double alpha) {
  if (trends.empty()) return "";
  const Trend& top = trends.front();
  const double level = alpha / static_cast<double>(trends.size());
  const std::string kind = top.sensor.substr(0, top.sensor.find_last_of(' '));
  std::vector<const Trend*> alike;  // the same sensor kind against the same quantity, significant
  for (const Trend& t : trends) {
    if (t.against == top.against && t.cable >= 0 && top.cable >= 0 &&
        t.sensor.substr(0, t.sensor.find_last_of(' ')) == kind && (&t == &top || t.p_value < level)) {
      alike.push_back(&t);
    }
  }
  bool up = true, down = true;
  for (const Trend* t : alike) (t->slope > 0 ? down : up) = false;
  if (alike.empty()) up = top.slope > 0, down = !up;
  const char* verb = up ? "grow" : down ? "fall" : "change";
  std::string text;
  if (top.cable < 0) {
    text = top.sensor + " residuals " + verb + " with " + plain(top.against);
  } else {
    std::sort(alike.begin(), alike.end(), [](const Trend* a, const Trend* b) { return a->cable < b->cable; });
    std::string cables;
    for (std::size_t k = 0; k < alike.size(); ++k) {
      cables += (k == 0 ? "" : k + 1 == alike.size() ? " and " : ", ") + std::to_string(alike[k]->cable);
    }
    text = kind + " residuals " + verb + " with " + plain(top.against) + " on cable" + (alike.size() > 1 ? "s " : " ") +
           cables;
  }
  return text + format(" (%s%s, t = %+.1f, p = %.1g)", top.cable >= 0 ? format("cable %d: ", top.cable).c_str() : "",
                       change_text(top).c_str(), top.t_statistic, top.p_value);
}

NormalisedResiduals normalised_residuals(const Robot& robot, const HeldOutEvaluation& held_out) {
  NormalisedResiduals out;
  for (const HeldOutPose& pose : held_out.poses) {
    const SampleSigmas sigma = reading_sigmas(robot, pose.sample);
    for (int i = 0; i < kCableCount; ++i) {
      if (!pose.sample.encoder_left_out[i]) out.encoder.push_back(pose.prediction.encoder_residual_m[i] / sigma.encoder_m[i]);
    }
    if (!pose.sample.force_left_out) out.force.push_back(pose.prediction.force_residual_n / sigma.force_n);
  }
  return out;
}

}  // namespace cdpr::report
