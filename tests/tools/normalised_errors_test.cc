// Per-run honesty statistics of a fit's sigmas (cdpr-accuracy/normalised_errors.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>

#include "cdpr-accuracy/normalised_errors.h"

namespace cdpr::accuracy {
namespace {

constexpr int kParameters = 16;

// Equal correlation rho between all parameters, sigmas 1..16 mm.
Eigen::MatrixXd covariance(double rho, Eigen::VectorXd& sigma) {
  sigma = Eigen::VectorXd::LinSpaced(kParameters, 1e-3, 16e-3);
  Eigen::MatrixXd correlation = Eigen::MatrixXd::Constant(kParameters, kParameters, rho);
  correlation.diagonal().setOnes();
  return sigma.asDiagonal() * correlation * sigma.asDiagonal();
}

TEST(NormalisedErrors, IndependentErrorsGiveTheChiSquareSpreadOfTheRms) {
  // GIVEN uncorrelated parameters and an error of exactly one sigma each
  Eigen::VectorXd sigma;
  const Eigen::MatrixXd c = covariance(0.0, sigma);
  // WHEN judged
  const NormalisedErrors e = normalised_errors(sigma, sigma, c);
  // THEN RMS and Mahalanobis are both 1, and chi-square(16)/16 leaves about
  // 5 % of honest runs outside 0.7-1.5 (P(chi2_16 < 7.84) + P(chi2_16 > 36))
  EXPECT_EQ(e.count, kParameters);
  EXPECT_NEAR(e.rms, 1.0, 1e-12);
  EXPECT_NEAR(e.mahalanobis, 1.0, 1e-12);
  EXPECT_NEAR(e.p_outside, 0.049, 0.006);
  EXPECT_NEAR(e.rms_q05, std::sqrt(7.962 / 16), 0.01);
  EXPECT_NEAR(e.rms_q95, std::sqrt(26.296 / 16), 0.01);
}

// Each of `runs` runs judged against `c`, its errors drawn from `scale`^2 c.
std::vector<NormalisedErrors> judged_runs(const Eigen::MatrixXd& c, const Eigen::VectorXd& sigma, double scale,
                                          int runs, std::uint64_t seed) {
  const Eigen::MatrixXd l = c.llt().matrixL();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<NormalisedErrors> out;
  for (int run = 0; run < runs; ++run) {
    Eigen::VectorXd w(kParameters);
    for (double& x : w) x = scale * normal(rng);
    out.push_back(normalised_errors(l * w, sigma, c));
  }
  return out;
}

TEST(NormalisedErrors, CorrelatedHonestErrorsScatterTheRmsButNotTheMahalanobis) {
  // GIVEN parameters correlated 0.5 with each other, and errors drawn from exactly that covariance
  Eigen::VectorXd sigma;
  const Eigen::MatrixXd c = covariance(0.5, sigma);
  constexpr int kRuns = 200;
  int rms_outside = 0, mahalanobis_outside = 0;
  double expected = 0.0, mahalanobis = 0.0, rank = 0.0;
  // WHEN each run is judged
  for (const NormalisedErrors& e : judged_runs(c, sigma, 1.0, kRuns, 7)) {
    rms_outside += e.rms < kHonestRmsLow || e.rms > kHonestRmsHigh;
    mahalanobis_outside += std::sqrt(e.mahalanobis) < kHonestRmsLow || std::sqrt(e.mahalanobis) > kHonestRmsHigh;
    expected += e.p_outside / kRuns;
    mahalanobis += e.mahalanobis / kRuns;
    rank += e.rms_rank / kRuns;
  }
  // THEN the RMS leaves the bounds far more often than the independent 5 %,
  // as often as the covariance predicts
  EXPECT_GT(expected, 0.2);
  EXPECT_NEAR(static_cast<double>(rms_outside) / kRuns, expected, 0.08);
  EXPECT_NEAR(rank, 0.5, 0.05);
  // AND the Mahalanobis statistic keeps the chi-square(16)/16 spread
  EXPECT_NEAR(mahalanobis, 1.0, 0.07);
  EXPECT_NEAR(static_cast<double>(mahalanobis_outside) / kRuns, 0.049, 0.04);
}

TEST(NormalisedErrors, SigmasTooSmallShowInBothStatistics) {
  // GIVEN errors twice what the (correlated) covariance allows
  Eigen::VectorXd sigma;
  const Eigen::MatrixXd c = covariance(0.5, sigma);
  constexpr int kRuns = 100;
  double mahalanobis = 0.0, rank = 0.0;
  // WHEN each run is judged
  for (const NormalisedErrors& e : judged_runs(c, sigma, 2.0, kRuns, 11)) {
    mahalanobis += e.mahalanobis / kRuns;
    rank += e.rms_rank / kRuns;
  }
  // THEN the Mahalanobis mean is about 4 and the RMS ranks high
  EXPECT_NEAR(mahalanobis, 4.0, 0.3);
  EXPECT_GT(rank, 0.8);
}

TEST(NormalisedErrors, NothingStatedWithoutACovariance) {
  Eigen::VectorXd sigma;
  covariance(0.0, sigma);
  EXPECT_EQ(normalised_errors(sigma, sigma, Eigen::MatrixXd()).count, 0);
}

}  // namespace
}  // namespace cdpr::accuracy
