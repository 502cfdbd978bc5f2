#include "src/report/ellipse.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>

namespace cdpr::report {

Ellipse sigma_ellipse(const Eigen::Matrix2d& covariance, double k) {
  const Eigen::Matrix2d symmetric = 0.5 * (covariance + covariance.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(symmetric);
  const Eigen::Vector2d values = solver.eigenvalues();  // ascending
  const Eigen::Vector2d major_axis = solver.eigenvectors().col(1);
  Ellipse e;
  e.major = k * std::sqrt(std::max(0.0, values(1)));
  e.minor = k * std::sqrt(std::max(0.0, values(0)));
  e.angle_rad = std::atan2(major_axis.y(), major_axis.x());
  if (e.angle_rad > std::numbers::pi / 2) e.angle_rad -= std::numbers::pi;
  if (e.angle_rad <= -std::numbers::pi / 2) e.angle_rad += std::numbers::pi;
  return e;
}

std::vector<Eigen::Vector2d> ellipse_points(const Eigen::Vector2d& center, const Ellipse& e, int count) {
  std::vector<Eigen::Vector2d> points;
  const double c = std::cos(e.angle_rad), s = std::sin(e.angle_rad);
  for (int j = 0; j < count; ++j) {
    const double t = 2.0 * std::numbers::pi * j / count;
    const double u = e.major * std::cos(t), v = e.minor * std::sin(t);
    points.emplace_back(center.x() + c * u - s * v, center.y() + s * u + c * v);
  }
  return points;
}

}  // namespace cdpr::report
