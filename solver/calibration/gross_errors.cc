#include "solver/calibration/gross_errors.h"

#include <algorithm>
#include <cmath>

namespace cdpr {
namespace {

// 1.4826 median |r| over the readings of one kind, at least 1.
double robust_spread(const std::vector<ReadingResidual>& residuals, SensorKind kind) {
  std::vector<double> sizes;
  for (const ReadingResidual& r : residuals) {
    if (r.sensor == kind) sizes.push_back(std::abs(r.whitened));
  }
  if (sizes.empty()) return 1.0;
  const auto middle = sizes.begin() + static_cast<std::ptrdiff_t>(sizes.size() / 2);
  std::nth_element(sizes.begin(), middle, sizes.end());
  return std::max(1.0, 1.4826 * *middle);
}

std::vector<SensorReading> normalised(const std::vector<ReadingResidual>& residuals) {
  const ReadingSpreads spreads = reading_spreads(residuals);
  std::vector<SensorReading> out;
  for (const ReadingResidual& r : residuals) out.push_back({r.row, r.sensor, r.cable, r.whitened / spreads.of(r.sensor)});
  return out;
}

}  // namespace

ReadingSpreads reading_spreads(const std::vector<ReadingResidual>& residuals) {
  return {robust_spread(residuals, SensorKind::kEncoder), robust_spread(residuals, SensorKind::kForce)};
}

std::vector<SensorReading> gross_errors(const std::vector<ReadingResidual>& residuals, double threshold_sigma) {
  std::vector<SensorReading> flagged;
  for (const SensorReading& r : normalised(residuals)) {
    if (std::abs(r.value) > threshold_sigma) flagged.push_back(r);
  }
  std::sort(flagged.begin(), flagged.end(),
            [](const SensorReading& a, const SensorReading& b) { return std::abs(a.value) > std::abs(b.value); });
  return flagged;
}

double largest_normalised_residual(const std::vector<ReadingResidual>& residuals) {
  double largest = 0.0;
  for (const SensorReading& r : normalised(residuals)) largest = std::max(largest, std::abs(r.value));
  return largest;
}

void settle_groups(std::vector<SensorReading>& readings) {
  for (SensorReading& r : readings) {
    if (r.group == 0) continue;
    const auto members = std::count_if(readings.begin(), readings.end(), [&](const SensorReading& o) {
      return o.row == r.row && o.group == r.group;
    });
    if (members < 2) r.group = 0;
  }
}

std::vector<SensorReading> confirm_left_out(const std::vector<SensorReading>& candidates,
                                            const std::vector<SensorReading>& predicted, bool refit_ok,
                                            double bar_sigma) {
  auto prediction = [&](const SensorReading& r) -> const SensorReading* {
    if (!refit_ok) return nullptr;
    const auto p = std::find_if(predicted.begin(), predicted.end(), [&](const SensorReading& q) {
      return q.row == r.row && q.sensor == r.sensor && q.cable == r.cable;
    });
    return p != predicted.end() && std::isfinite(p->value) ? &*p : nullptr;
  };
  // A reading stays out on its own evidence: predicted beyond the bar, or
  // flagged with no prediction to test.
  auto stays_out = [&](const SensorReading& r) {
    const SensorReading* p = prediction(r);
    return p ? std::abs(p->value) > bar_sigma : std::isfinite(r.value);
  };
  std::vector<SensorReading> confirmed;
  for (const SensorReading& r : candidates) {
    if (r.group != 0) {
      // A suspect group stays out whole while any member does: the data
      // could not tell which of them is wrong, and with all of them out the
      // row's pose is fitted to the rest alone, so a member predicted within
      // the bar is no evidence that it is the good one.
      const bool group_out = std::any_of(candidates.begin(), candidates.end(), [&](const SensorReading& o) {
        return o.row == r.row && o.group == r.group && stays_out(o);
      });
      if (group_out) confirmed.push_back(r);
      continue;
    }
    const SensorReading* p = prediction(r);
    if (!p) {
      if (std::isfinite(r.value)) confirmed.push_back(r);
      continue;
    }
    if (std::abs(p->value) <= bar_sigma) continue;
    if (std::isnan(r.value)) {
      // A hypothesis row's readings were all left out, so each is predicted
      // from its row's pose prior alone and good ones look bad too: only the
      // one predicted farthest off stays out.
      const bool farthest = std::none_of(candidates.begin(), candidates.end(), [&](const SensorReading& o) {
        const SensorReading* q = std::isnan(o.value) && o.row == r.row ? prediction(o) : nullptr;
        return q && std::abs(q->value) > std::abs(p->value);
      });
      if (!farthest) continue;
    }
    confirmed.push_back(r);
    if (std::isnan(r.value)) confirmed.back().value = p->value;
  }
  return confirmed;
}

}  // namespace cdpr
