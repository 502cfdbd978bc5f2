#include "residual_trends.h"

#include <algorithm>
#include <cmath>

namespace cdpr::tools {

std::vector<ResidualSeries> residual_series(const HeldOutEvaluation& held_out) {
  std::vector<ResidualSeries> series;
  for (int i = 0; i < kCableCount; ++i) {
    const std::string encoder = "encoder " + std::to_string(i);
    ResidualSeries by_length{encoder, "cable length [m]", "m", {}, {}};
    ResidualSeries by_tension{encoder, "cable tension [N]", "m", {}, {}};
    ResidualSeries by_height{encoder, "platform height [m]", "m", {}, {}};
    ResidualSeries height{"height " + std::to_string(i), "platform height [m]", "m", {}, {}};
    for (const HeldOutPose& pose : held_out.poses) {
      const double r = pose.prediction.encoder_residual_m[i];
      const double z = pose.world_T_platform.position_world.z();
      by_length.x.push_back(pose.prediction.payout_m[i]);
      by_length.residual.push_back(r);
      by_tension.x.push_back(pose.prediction.tension_n[i]);
      by_tension.residual.push_back(r);
      by_height.x.push_back(z);
      by_height.residual.push_back(r);
      height.x.push_back(z);
      height.residual.push_back(pose.prediction.height_residual_m[i]);
    }
    for (ResidualSeries* s : {&by_length, &by_tension, &by_height, &height}) series.push_back(std::move(*s));
  }
  ResidualSeries force{"load cell", "reference tension [N]", "N", {}, {}};
  ResidualSeries force_height{"load cell", "platform height [m]", "N", {}, {}};
  for (const HeldOutPose& pose : held_out.poses) {
    force.x.push_back(pose.sample.force_n);
    force.residual.push_back(pose.prediction.force_residual_n);
    force_height.x.push_back(pose.world_T_platform.position_world.z());
    force_height.residual.push_back(pose.prediction.force_residual_n);
  }
  series.push_back(std::move(force));
  series.push_back(std::move(force_height));
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
    Trend t{s.sensor, s.against, s.unit, sxy / sxx, sxy / std::sqrt(sxx * syy), 0.0};
    t.t_statistic = t.correlation * std::sqrt((n - 2.0) / std::max(1e-12, 1.0 - t.correlation * t.correlation));
    trends.push_back(t);
  }
  std::stable_sort(trends.begin(), trends.end(),
                   [](const Trend& a, const Trend& b) { return std::abs(a.t_statistic) > std::abs(b.t_statistic); });
  return trends;
}

}  // namespace cdpr::tools
