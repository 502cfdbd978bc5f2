#include "solver/operation/refit.h"

#include <cmath>

#include "solver/nls/levenberg_marquardt.h"
#include "solver/nls/problem.h"
#include "solver/operation/calibration_variables.h"
#include "solver/operation/rest_problem.h"

namespace cdpr {
namespace {

std::optional<Calibration> refused(std::string* why, const std::string& what) {
  if (why) *why = what;
  return std::nullopt;
}

std::vector<Key> refitted_keys(const RefitRequest& request) {
  if (request.offsets_only) return {OffsetKey(0), OffsetKey(1), OffsetKey(2), OffsetKey(3)};
  if (request.term == FaultTerm::kAnchor) return {AnchorKey(request.cable)};
  return {OffsetKey(request.cable)};
}

}  // namespace

RefitRequest refit_request_for(const StaleFinding& finding) {
  RefitRequest r;
  switch (finding.term.term) {
    case FaultTerm::kEncoderOffset:
    case FaultTerm::kCableElongation:
      r.offsets_only = false;
      r.term = FaultTerm::kEncoderOffset;
      r.cable = finding.term.cable;
      break;
    case FaultTerm::kAnchor:
      r.offsets_only = false;
      r.term = FaultTerm::kAnchor;
      r.cable = finding.term.cable;
      break;
    case FaultTerm::kLoad:
    case FaultTerm::kLoadCellBias: break;
  }
  return r;
}

std::optional<Calibration> refit_from_rests(const Robot& robot, const Calibration& committed,
                                            const std::vector<Sample>& rests, const RefitRequest& request,
                                            const RefitOptions& options, std::string* why) {
  if (rests.empty()) return refused(why, "no rests to re-fit from");
  std::string problem_why;
  const std::optional<std::vector<Effect>> effects = calibration_effects(committed, &problem_why);
  if (!effects) return refused(why, problem_why);
  if (!request.offsets_only && (request.cable < 0 || request.cable >= kCableCount)) {
    return refused(why, "no such cable " + std::to_string(request.cable));
  }

  Problem problem;
  if (!add_calibration_variables(problem, committed, *effects, CalibrationUncertainty::kHeldConstant, &problem_why)) {
    return refused(why, problem_why);
  }
  const std::vector<Key> free_keys = refitted_keys(request);
  for (const Key& key : free_keys) problem.set_constant(key, false);
  for (std::size_t k = 0; k < rests.size(); ++k) {
    const Sample& rest = rests[k];
    if (!has_measured_pose(rest)) {
      return refused(why, "rest " + std::to_string(rest.id) + " has no measured pose: the re-fit needs the onboard pose");
    }
    const Pose measured{rest.position_world, rest.world_R_platform};
    const std::optional<RestStart> start = rest_start(robot, committed, rest, measured, &problem_why);
    if (!start) return refused(why, "rest " + std::to_string(rest.id) + ": " + problem_why);
    const int index = static_cast<int>(k);
    problem.add_pose(PoseKey(index), Pose{measured.position_world, start->world_T_platform.world_R_platform});
    problem.add_vector(ReferenceForceKey(index), start->reference_force);
    problem.add_factor(make_rest_factor(robot, index, rest, *effects, options.height_sigma_m));
    problem.add_factor(make_measured_pose_factor(robot, index, rest));
  }

  SolverOptions solver_options;
  solver_options.max_iterations = options.max_iterations;
  LevenbergMarquardt lm(problem, solver_options);
  const SolverSummary summary = lm.solve();
  if (!summary.usable()) return refused(why, "the re-fit failed: " + summary.message);
  const Eigen::MatrixXd covariance = lm.covariance(free_keys);
  if (covariance.rows() == 0 || !covariance.allFinite()) {
    return refused(why, "the re-fitted term is not observable from these rests");
  }

  Calibration out = committed;
  out.samples = static_cast<int>(rests.size());
  out.fit.cost_initial = summary.initial_cost;
  out.fit.cost_final = summary.final_cost;
  out.fit.iterations = summary.iterations;
  out.model_warning.clear();
  out.rejected.clear();
  out.run.reset();
  int row = 0;
  for (const Key& key : free_keys) {
    WinchCalibration& w = out.winches[key.index];
    const Eigen::VectorXd value = problem.vector(key);
    if (key.kind == VariableKind::kOffset) {
      w.offset_m = value(0);
      w.offset_sigma_m = std::sqrt(covariance(row, row));
      row += 1;
    } else {
      w.anchor_world = value.head<3>();
      w.anchor_sigma = covariance.block<3, 3>(row, row).diagonal().cwiseSqrt();
      row += 3;
    }
  }
  return out;
}

}  // namespace cdpr
