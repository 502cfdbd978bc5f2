#include "src/report/ellipse.h"

#include <cmath>
#include <numbers>

#include <Eigen/LU>
#include <gtest/gtest.h>

namespace cdpr::report {
namespace {

TEST(SigmaEllipse, DiagonalCovarianceGivesAxisAlignedSemiAxes) {
  // GIVEN sigma_x = 3 mm, sigma_y = 1 mm, uncorrelated
  const Eigen::Matrix2d cov = Eigen::Vector2d(9e-6, 1e-6).asDiagonal();
  // WHEN the 1- and 3-sigma ellipses are taken
  const Ellipse one = sigma_ellipse(cov, 1.0), three = sigma_ellipse(cov, 3.0);
  // THEN the semi-axes are k sigma along x and y
  EXPECT_NEAR(one.major, 3e-3, 1e-12);
  EXPECT_NEAR(one.minor, 1e-3, 1e-12);
  EXPECT_NEAR(std::abs(one.angle_rad), 0.0, 1e-12);
  EXPECT_NEAR(three.major, 9e-3, 1e-12);
  EXPECT_NEAR(three.minor, 3e-3, 1e-12);
}

TEST(SigmaEllipse, CorrelatedCovarianceTiltsTheMajorAxis) {
  // GIVEN a covariance R diag(4, 1) R' with R a rotation by 30 degrees
  const double a = std::numbers::pi / 6;
  Eigen::Matrix2d r;
  r << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  const Eigen::Matrix2d cov = r * Eigen::Vector2d(4.0, 1.0).asDiagonal() * r.transpose();
  const Ellipse e = sigma_ellipse(cov, 1.0);
  // THEN the major axis is 2 along 30 degrees, the minor 1
  EXPECT_NEAR(e.major, 2.0, 1e-12);
  EXPECT_NEAR(e.minor, 1.0, 1e-12);
  EXPECT_NEAR(e.angle_rad, a, 1e-12);
}

TEST(SigmaEllipse, PointsLieAtMahalanobisDistanceK) {
  Eigen::Matrix2d cov;
  cov << 2.0, -0.8, -0.8, 1.0;
  const Eigen::Vector2d center(10.0, -5.0);
  for (double k : {1.0, 3.0}) {
    for (const Eigen::Vector2d& p : ellipse_points(center, sigma_ellipse(cov, k), 36)) {
      const Eigen::Vector2d d = p - center;
      EXPECT_NEAR(std::sqrt(d.dot(cov.inverse() * d)), k, 1e-9);
    }
  }
}

TEST(SigmaEllipse, RoundingNegativeEigenvalueCountsAsZero) {
  Eigen::Matrix2d cov;
  cov << 1.0, 1.0, 1.0, 1.0 - 1e-15;
  const Ellipse e = sigma_ellipse(cov, 1.0);
  EXPECT_NEAR(e.major, std::sqrt(2.0), 1e-6);
  EXPECT_GE(e.minor, 0.0);
  EXPECT_FALSE(std::isnan(e.minor));
}

}  // namespace
}  // namespace cdpr::report
