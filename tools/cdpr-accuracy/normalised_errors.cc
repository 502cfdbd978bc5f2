#include "cdpr-accuracy/normalised_errors.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "solver/calibration/chi_square.h"

namespace cdpr::accuracy {
namespace {

// Draws of the honest RMS: the probabilities to within about 0.005.
constexpr int kDraws = 10000;

}  // namespace

NormalisedErrors normalised_errors(const Eigen::VectorXd& error, const Eigen::VectorXd& sigma,
                                   const Eigen::MatrixXd& covariance) {
  NormalisedErrors out;
  const Eigen::Index n = error.size();
  if (n == 0 || sigma.size() != n || covariance.rows() < n || covariance.cols() < n || (sigma.array() <= 0.0).any()) {
    return out;
  }
  const Eigen::VectorXd fit_sigma = covariance.topLeftCorner(n, n).diagonal().cwiseMax(0.0).cwiseSqrt();
  if ((fit_sigma.array() <= 0.0).any()) return out;
  const Eigen::MatrixXd correlation =
      fit_sigma.cwiseInverse().asDiagonal() * covariance.topLeftCorner(n, n) * fit_sigma.cwiseInverse().asDiagonal();
  const Eigen::VectorXd z = error.cwiseQuotient(sigma);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(correlation);
  if (ldlt.info() != Eigen::Success) return out;
  out.count = static_cast<int>(n);
  out.rms = std::sqrt(z.squaredNorm() / n);
  out.mahalanobis = z.dot(ldlt.solve(z)) / n;
  out.mahalanobis_p = chi_square_upper_tail(out.mahalanobis * n, out.count);

  const Eigen::VectorXd lambda =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(correlation, Eigen::EigenvaluesOnly).eigenvalues().cwiseMax(0.0);
  std::mt19937_64 rng(0x5eed);
  std::normal_distribution<double> normal;
  std::vector<double> rms(kDraws);
  for (double& r : rms) {
    double sum = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) sum += lambda(k) * std::pow(normal(rng), 2);
    r = std::sqrt(sum / n);
  }
  std::sort(rms.begin(), rms.end());
  const auto quantile = [&](double q) { return rms[static_cast<std::size_t>(q * (kDraws - 1) + 0.5)]; };
  out.rms_q05 = quantile(0.05);
  out.rms_q95 = quantile(0.95);
  const auto below = [&](double x) {
    return static_cast<double>(std::lower_bound(rms.begin(), rms.end(), x) - rms.begin()) / kDraws;
  };
  out.p_outside = below(kHonestRmsLow) + 1.0 - below(kHonestRmsHigh);
  out.rms_rank = below(out.rms);
  return out;
}

}  // namespace cdpr::accuracy
