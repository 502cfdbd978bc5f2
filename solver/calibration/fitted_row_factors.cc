#include "solver/calibration/fitted_row_factors.h"

#include "solver/calibration/effect_pose_factor.h"
#include "solver/calibration/pose_prior_factor.h"

namespace cdpr {

bool evaluate_fitted_row(const Robot& robot, const FittedRow& row, int index, double height_sigma_m, const Loss& loss,
                         const std::vector<Effect>& effects, double* pose, double* force,
                         const double* const* parameters, const FittedRowOutput& out) {
  const Eigen::Vector3d& p = row.world_T_platform.position_world;
  const Eigen::Quaterniond& q = row.world_T_platform.world_R_platform;
  const double fitted_pose[] = {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()};
  for (int i = 0; i < 7; ++i) pose[i] = fitted_pose[i];
  force[0] = row.reference_force(0);
  force[1] = row.reference_force(1);
  const SampleSigmas sigma = reading_sigmas(robot, row.sample);
  const PosePriorFactor prior(index, {row.sample.position_world, row.sample.world_R_platform}, sigma.position_m,
                              sigma.orientation_rad, loss);
  const EffectPoseFactor factor(robot, index, row.sample, height_sigma_m, loss, effects);
  double cost = 0.0;
  return prior.evaluate(parameters, out.prior_residual, out.prior_jacobians, &cost) &&
         factor.evaluate(parameters, out.residual, out.jacobians, &cost);
}

}  // namespace cdpr
