#include "solver/initial_guess.h"

#include <cmath>
#include <limits>

#include "solver/static_pose_factor.h"

namespace cdpr {

Eigen::Vector2d paper_reference_force_guess(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Sample& sample) {
  const int ref = robot.reference_cable;
  const Eigen::Vector3d attachment_world =
      sample.world_R_platform * robot.winches[ref].attachment_platform + sample.position_world;
  const Eigen::Vector3d chord = attachment_world - anchors[ref];
  const double horizontal = std::hypot(chord.x(), chord.y());
  const double f_v0 = robot.platform_mass_kg * robot.gravity_mps2 / 4.0;  // Eq. (17)
  // Eq. (18): cos(alpha) = s_c^T chord / |chord| = horizontal / |chord|.
  const double alpha = std::acos(std::min(1.0, horizontal / chord.norm()));
  return {f_v0 / std::tan(alpha), f_v0};
}

Eigen::Vector2d rigid_reference_force_guess(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Sample& sample) {
  Eigen::Matrix<double, 6, kCableCount> wrench_per_tension;
  Eigen::Matrix<double, 3, kCableCount> directions;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d lever = sample.world_R_platform * robot.winches[i].attachment_platform;
    directions.col(i) = (anchors[i] - (sample.position_world + lever)).normalized();
    wrench_per_tension.col(i) << directions.col(i), lever.cross(directions.col(i));
  }
  const double weight = robot.platform_mass_kg * robot.gravity_mps2;
  Eigen::Matrix<double, 6, 1> wrench;
  wrench << 0.0, 0.0, weight, (sample.world_R_platform * robot.center_of_mass_platform).cross(Eigen::Vector3d(0, 0, weight));
  const Eigen::Vector4d tensions = wrench_per_tension.colPivHouseholderQr().solve(wrench);
  const Eigen::Vector3d u = directions.col(robot.reference_cable);
  const double tension = std::max(tensions(robot.reference_cable), 0.25 * weight);
  return {tension * std::hypot(u.x(), u.y()), tension * u.z()};
}

std::optional<Eigen::Vector2d> refine_reference_force(const Robot& robot,
                                                      const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                      const Sample& sample, const Eigen::Vector2d& guess,
                                                      double sigma_height_m) {
  const StaticPoseFactor factor(robot, 0, sample, sigma_height_m, Loss{});
  constexpr int kRows = StaticPoseFactor::kResidualDim;
  const double pose[7] = {sample.position_world.x(), sample.position_world.y(), sample.position_world.z(),
                          sample.world_R_platform.w(), sample.world_R_platform.x(), sample.world_R_platform.y(),
                          sample.world_R_platform.z()};
  const double zero_offset[1] = {0.0};
  Eigen::Vector2d force = guess;
  const double* parameters[StaticPoseFactor::kKeyCount] = {pose, force.data()};
  for (int i = 0; i < kCableCount; ++i) {
    parameters[2 + i] = anchors[i].data();
    parameters[2 + kCableCount + i] = zero_offset;
  }
  Eigen::Matrix<double, kRows, 1> residual;
  Eigen::Matrix<double, kRows, 2, Eigen::RowMajor> d_force;
  double* jacobians[StaticPoseFactor::kKeyCount] = {nullptr, d_force.data()};

  // Only the height and force rows constrain the force; encoder rows carry
  // the still unknown offsets.
  auto height_and_force_cost = [&](double* const* jac) -> std::optional<double> {
    double cost = 0.0;
    if (!factor.evaluate(parameters, residual.data(), jac, &cost)) return std::nullopt;
    return residual.tail<kCableCount + 1>().squaredNorm();
  };
  std::optional<double> cost = height_and_force_cost(jacobians);
  if (!cost) return std::nullopt;
  double damping = 1e-3;
  for (int iteration = 0; iteration < 50 && damping < 1e12; ++iteration) {
    const auto J = d_force.bottomRows<kCableCount + 1>();
    const Eigen::Vector2d gradient = J.transpose() * residual.tail<kCableCount + 1>();
    Eigen::Matrix2d H = J.transpose() * J;
    H.diagonal() *= 1.0 + damping;
    const Eigen::Vector2d step = -H.ldlt().solve(gradient);
    const Eigen::Vector2d previous = force;
    force += step;
    const std::optional<double> trial = height_and_force_cost(nullptr);
    if (trial && *trial < *cost) {
      const bool converged = *cost - *trial < 1e-12 * (1.0 + *cost);
      cost = height_and_force_cost(jacobians);
      damping = std::max(damping / 10.0, 1e-9);
      if (converged) break;
    } else {
      force = previous;
      height_and_force_cost(jacobians);
      damping *= 10.0;
    }
  }
  return force;
}

std::optional<Eigen::Vector2d> search_feasible_reference_force(const Robot& robot,
                                                               const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                                               const Sample& sample, double sigma_height_m) {
  const StaticPoseFactor factor(robot, 0, sample, sigma_height_m, Loss{});
  const double pose[7] = {sample.position_world.x(), sample.position_world.y(), sample.position_world.z(),
                          sample.world_R_platform.w(), sample.world_R_platform.x(), sample.world_R_platform.y(),
                          sample.world_R_platform.z()};
  const double zero_offset[1] = {0.0};
  Eigen::Vector2d force;
  const double* parameters[StaticPoseFactor::kKeyCount] = {pose, force.data()};
  for (int i = 0; i < kCableCount; ++i) {
    parameters[2 + i] = anchors[i].data();
    parameters[2 + kCableCount + i] = zero_offset;
  }
  Eigen::Matrix<double, StaticPoseFactor::kResidualDim, 1> residual;
  // A suspended platform's cables each carry at most a few times its weight.
  const double weight = robot.platform_mass_kg * robot.gravity_mps2;
  constexpr int kSteps = 60;
  std::optional<Eigen::Vector2d> best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int a = 1; a <= kSteps; ++a) {
    for (int b = 0; b <= kSteps; ++b) {
      force = Eigen::Vector2d(4.0 * weight * a / kSteps, weight * (-1.0 + 3.0 * b / kSteps));
      double cost = 0.0;
      if (!factor.evaluate(parameters, residual.data(), nullptr, &cost)) continue;
      const double height_and_force = residual.tail<kCableCount + 1>().squaredNorm();
      if (height_and_force < best_cost) {
        best_cost = height_and_force;
        best = force;
      }
    }
  }
  return best;
}

std::array<double, kCableCount> mean_offsets(const std::vector<Sample>& samples,
                                             const std::vector<std::array<double, kCableCount>>& lengths) {
  std::array<double, kCableCount> offsets{};
  for (std::size_t k = 0; k < samples.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) offsets[i] += samples[k].encoder_m[i] - lengths[k][i];
  }
  for (double& offset : offsets) offset /= static_cast<double>(samples.size());
  return offsets;
}

}  // namespace cdpr
