#pragma once
// How honest one fit's sigmas are, judged from its own errors against the
// truth (docs/calibration.md "Honest sigmas, run by run").
//
// The error/sigma RMS of a run's anchor axes and offsets is a poor per-run
// test: the errors share the frame, the platform poses and the offsets, so
// they are strongly correlated, and even exactly honest sigmas give an RMS
// that scatters far more than chi-square(n)/n suggests. This states what
// the fit's own covariance C (the correlations of calibrate()'s
// global_covariance with the reported sigmas) predicts for that RMS, and
// the statistic that does follow chi-square(n) / n when C is honest: the
// Mahalanobis e' C^-1 e / n.

#include <Eigen/Core>

namespace cdpr::accuracy {

// Bounds of the per-run RMS that the acceptance asks for.
inline constexpr double kHonestRmsLow = 0.7, kHonestRmsHigh = 1.5;

struct NormalisedErrors {
  int count = 0;               // errors (0: no covariance, nothing stated)
  double rms = 0.0;            // sqrt(mean of (e_j / sigma_j)^2)
  double mahalanobis = 0.0;    // e' C^-1 e / count
  double mahalanobis_p = 1.0;  // its upper-tail probability under chi-square(count) / count
  // The RMS that honest sigmas with these correlations give: its 5 % and
  // 95 % quantiles, the probability that it falls outside [kHonestRmsLow,
  // kHonestRmsHigh], and where this run's RMS falls in it (P(RMS <= rms):
  // uniform over runs when the sigmas are honest).
  double rms_q05 = 0.0, rms_q95 = 0.0;
  double p_outside = 0.0;
  double rms_rank = 0.0;
};

// `error`: estimate minus truth; `sigma`: the reported 1-sigma of each;
// `covariance`: the fit's covariance of the same parameters (only its
// correlations are used). The RMS distribution is that of sqrt(sum_k
// lambda_k w_k^2 / n), lambda the eigenvalues of the correlation matrix and
// w standard normal, from a fixed number of deterministic draws.
NormalisedErrors normalised_errors(const Eigen::VectorXd& error, const Eigen::VectorXd& sigma,
                                   const Eigen::MatrixXd& covariance);

}  // namespace cdpr::accuracy
