#include "src/calibration/waypoint_tour.h"

#include <algorithm>
#include <cmath>

namespace cdpr::calibration {
namespace {

// Improvements smaller than this [m] are round-off: stops 2-opt from cycling.
constexpr double kMinGainM = 1e-9;

}  // namespace

double winch_travel_m(const Robot& robot, const AnchorPositions& anchors, const Pose& from, const Pose& to) {
  double travel_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d& b = robot.winches[i].attachment_platform;
    const double before_m = (anchors[i] - from.transform(b)).norm();
    const double after_m = (anchors[i] - to.transform(b)).norm();
    travel_m = std::max(travel_m, std::abs(after_m - before_m));
  }
  return travel_m;
}

std::vector<int> tour_order(const Robot& robot, const AnchorPositions& anchors, const Pose& start,
                            const std::vector<Pose>& stops, bool improve) {
  // Node 0 is the start, node k + 1 is stops[k].
  const int n = static_cast<int>(stops.size()) + 1;
  const auto pose = [&](int node) -> const Pose& { return node == 0 ? start : stops[node - 1]; };
  Eigen::MatrixXd cost(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) cost(a, b) = winch_travel_m(robot, anchors, pose(a), pose(b));
  }

  std::vector<int> route{0};
  std::vector<bool> visited(n, false);
  visited[0] = true;
  while (static_cast<int>(route.size()) < n) {
    int nearest = -1;
    for (int b = 1; b < n; ++b) {
      if (!visited[b] && (nearest < 0 || cost(route.back(), b) < cost(route.back(), nearest))) nearest = b;
    }
    visited[nearest] = true;
    route.push_back(nearest);
  }

  // 2-opt on the open route: reversing route[i..j] replaces the edges
  // (i-1, i) and (j, j+1) by (i-1, j) and (i, j+1); the last stop has no
  // successor, so reversing a tail costs only its first edge.
  for (bool better = improve; better;) {
    better = false;
    for (int i = 1; i + 1 < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        const bool tail = j + 1 == n;
        const double removed = cost(route[i - 1], route[i]) + (tail ? 0.0 : cost(route[j], route[j + 1]));
        const double added = cost(route[i - 1], route[j]) + (tail ? 0.0 : cost(route[i], route[j + 1]));
        if (added < removed - kMinGainM) {
          std::reverse(route.begin() + i, route.begin() + j + 1);
          better = true;
        }
      }
    }
  }
  std::vector<int> order;
  order.reserve(n - 1);
  for (int k = 1; k < n; ++k) order.push_back(route[k] - 1);
  return order;
}

double tour_travel_m(const Robot& robot, const AnchorPositions& anchors, const Pose& start,
                     const std::vector<Pose>& stops, const std::vector<int>& order) {
  double travel_m = 0.0;
  const Pose* at = &start;
  for (const int k : order) {
    travel_m += winch_travel_m(robot, anchors, *at, stops[k]);
    at = &stops[k];
  }
  return travel_m;
}

}  // namespace cdpr::calibration
