#include "solver/calibration/pose_design.h"

#include <limits>

#include <Eigen/Cholesky>

namespace cdpr {
namespace {

// Relative to one encoder reading's information: small enough not to favour
// any direction, large enough that the first, rank-deficient steps of the
// greedy choice have a finite variance (the unseen directions then dominate
// the sum, so they are filled first).
constexpr double kRidgeRelative = 1e-8;

DesignInformation ridge(const Robot& robot) {
  const double per_reading = 1.0 / (robot.noise.encoder_m * robot.noise.encoder_m);
  return kRidgeRelative * per_reading * DesignInformation::Identity();
}

DesignInformation covariance(const DesignInformation& information) {
  const Eigen::LDLT<DesignInformation> ldlt(information);
  if (ldlt.info() != Eigen::Success) {
    DesignInformation unknown = DesignInformation::Zero();
    unknown.diagonal().setConstant(std::numeric_limits<double>::infinity());
    return unknown;
  }
  return ldlt.solve(DesignInformation::Identity());
}

double variance_sum(const DesignInformation& information) { return covariance(information).trace(); }

}  // namespace

DesignInformation pose_information(const Robot& robot, const Pose& pose) {
  // Rows: one encoder reading per cable. Columns: design parameters, and the
  // pose tangent (d_p, d_theta) as a nuisance.
  Eigen::Matrix<double, kCableCount, kDesignParameters> j_parameters =
      Eigen::Matrix<double, kCableCount, kDesignParameters>::Zero();
  Eigen::Matrix<double, kCableCount, 6> j_pose;
  const Eigen::Matrix3d rotation = pose.world_R_platform.toRotationMatrix();
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d& b = robot.winches[i].attachment_platform;
    const Eigen::Vector3d u = (robot.winches[i].anchor_world - pose.transform(b)).normalized();
    j_parameters.block<1, 3>(i, 3 * i) = u.transpose();
    j_parameters(i, 3 * kCableCount + i) = 1.0;
    j_pose.block<1, 3>(i, 0) = -u.transpose();
    // The attachment R Exp(d) b moves by -R [b]x d, so the length changes by u^T R [b]x d.
    j_pose.block<1, 3>(i, 3) = u.transpose() * rotation * skew(b);
  }
  const double w_encoder = 1.0 / (robot.noise.encoder_m * robot.noise.encoder_m);
  Eigen::Matrix<double, 6, 1> prior;
  prior.head<3>().setConstant(1.0 / (robot.noise.position_m * robot.noise.position_m));
  prior.tail<3>().setConstant(1.0 / (robot.noise.orientation_rad * robot.noise.orientation_rad));

  // Products first, then scaled: GCC 12 at -O1 with the sanitizers warns
  // (maybe-uninitialized) on Eigen's scalar-times-transpose product expressions.
  const Eigen::Matrix<double, 6, kCableCount> j_pose_t = j_pose.transpose();
  Eigen::Matrix<double, 6, 6> i_pose = j_pose_t * j_pose;
  i_pose *= w_encoder;
  i_pose.diagonal() += prior;
  Eigen::Matrix<double, 6, kDesignParameters> i_cross = j_pose_t * j_parameters;
  i_cross *= w_encoder;
  DesignInformation i_parameters = j_parameters.transpose() * j_parameters;
  i_parameters *= w_encoder;
  // Schur complement: what is left about the parameters once the pose is estimated too.
  return i_parameters - i_cross.transpose() * i_pose.llt().solve(i_cross);
}

DesignInformation design_information(const Robot& robot, const std::vector<Pose>& poses) {
  DesignInformation total = ridge(robot);
  for (const Pose& pose : poses) total += pose_information(robot, pose);
  return total;
}

std::vector<int> choose_informative_poses(const Robot& robot, const std::vector<Pose>& candidates, int count) {
  std::vector<DesignInformation> information;
  information.reserve(candidates.size());
  for (const Pose& pose : candidates) information.push_back(pose_information(robot, pose));

  std::vector<int> chosen;
  std::vector<bool> taken(candidates.size(), false);
  DesignInformation total = ridge(robot);
  while (static_cast<int>(chosen.size()) < count) {
    int best = -1;
    double best_variance = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (taken[k]) continue;
      const double variance = variance_sum(total + information[k]);
      if (best < 0 || variance < best_variance) {
        best = static_cast<int>(k);
        best_variance = variance;
      }
    }
    if (best < 0) break;  // every candidate taken
    taken[best] = true;
    total += information[best];
    chosen.push_back(best);
  }
  return chosen;
}

double design_variance_sum(const Robot& robot, const std::vector<Pose>& poses) {
  return variance_sum(design_information(robot, poses));
}

DesignInformation design_covariance(const Robot& robot, const std::vector<Pose>& poses) {
  return covariance(design_information(robot, poses));
}

}  // namespace cdpr
