#pragma once
// The k-sigma ellipse of a 2-D normal from its covariance: the set where
// the Mahalanobis distance is k. Drawn around each fitted anchor in the
// reports' top view.

#include <vector>

#include <Eigen/Core>

namespace cdpr::report {

struct Ellipse {
  double major = 0.0, minor = 0.0;  // semi-axes, major >= minor >= 0
  double angle_rad = 0.0;           // of the major axis from +x, in (-pi/2, pi/2]
};

// Semi-axes k sqrt(eigenvalues) along the eigenvectors of `covariance`
// (symmetric; negative eigenvalues from rounding count as 0).
Ellipse sigma_ellipse(const Eigen::Matrix2d& covariance, double k);

// `count` points of the ellipse around `center`, counter-clockwise.
std::vector<Eigen::Vector2d> ellipse_points(const Eigen::Vector2d& center, const Ellipse& ellipse, int count);

}  // namespace cdpr::report
